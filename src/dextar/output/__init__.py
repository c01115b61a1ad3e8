"""Outputs: atomic file writing, figures, report."""
