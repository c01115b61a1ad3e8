# The compiled fused torque kernel (_kernel.c), built by pip where a C compiler is.
N_CONSTS: int
VERSION: int

def torques(consts: object, q: object, dq: object, ddq: object, out: object, /
            ) -> tuple[float, float, bool]: ...

def task_torques(consts: object, legs: tuple[float, float, float, float], P: object,
                 dP: object, ddP: object, dq: object, ddq: object, out: object, /
                 ) -> tuple[int, float, float, bool]: ...
