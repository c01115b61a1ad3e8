"""The compiled parts' one rule of use (``dynamics/_kernel.c``, ``laws/_reach.c``, optional
extensions built by pip where a C compiler is): a build is used only if it is of the
interface version its module calls, so that an old build left in place by an edit whose
build failed is set aside (the numpy or Python code runs instead)."""


def usable(module: object, version: int) -> bool:
    """Whether ``module`` is a build of interface ``version`` (None: not built)."""
    return module is not None and getattr(module, "VERSION", None) == version
