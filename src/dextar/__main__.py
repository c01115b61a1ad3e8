"""python -m dextar: the command line."""

from .cli import entry

if __name__ == "__main__":  # (importing the module, as the API docs do, runs nothing)
    entry()
