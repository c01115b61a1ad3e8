"""Choosing the robot: the design space, one design evaluated on a task, the Pareto front and
the Dask sweep."""
