"""The commands of the command line, one module each (see :mod:`dextar.commands.base`).

A new command is one module with ``NAME``, ``HELP``, ``add_arguments`` and ``run``, and its
name in :data:`COMMANDS`.
"""

#: The command modules, in the order ``dextar --help`` lists them.
COMMANDS = ("ik", "fk", "workspace", "plan", "torques", "simulate", "export", "program",
            "excite", "identify", "poses", "calibrate", "design", "run")
