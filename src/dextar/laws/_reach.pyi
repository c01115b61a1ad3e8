# The compiled reachability analysis (_reach.c), built by pip where a C compiler is.
VERSION: int

def reach(Gu: object, Gx: object, h: object, ds: object, x: object, /) -> int: ...
