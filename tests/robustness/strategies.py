"""Hypothesis strategies over configs (every table and key, with wrong types, huge and tiny
values, points outside the workspace, degenerate geometry, expressions with poles) and over
command-line arguments."""

from __future__ import annotations

from typing import Any

from hypothesis import strategies as st

FIN = st.floats(allow_nan=False, allow_infinity=False)
EXTREME = st.sampled_from([0.0, -0.0, -1.0, 1e-300, 1e-12, 1e12, 1e300, -1e300,
                           float("nan"), float("inf"), float("-inf")])
WRONG = st.one_of(st.text(max_size=6), st.booleans(), st.lists(st.integers(-3, 3), max_size=3),
                  st.dictionaries(st.sampled_from(["a", "x"]), st.integers(), max_size=1))


def number(lo: float, hi: float, clean: bool = False) -> st.SearchStrategy[Any]:
    """A sensible number in [lo, hi]; unless ``clean``, sometimes an extreme or a wrong
    type instead."""
    sensible = st.one_of(st.floats(lo, hi), st.integers(int(max(lo, -1e6)), int(min(hi, 1e6)))
                         ) if hi - lo >= 1 else st.floats(lo, hi)
    if clean:
        return sensible
    return st.one_of(*([sensible] * 8), EXTREME, WRONG)


def pair(lo: float, hi: float, clean: bool = False) -> st.SearchStrategy[Any]:
    """A number or a pair of numbers (unless ``clean``, sometimes of the wrong length)."""
    good = st.one_of(number(lo, hi, clean),
                     st.lists(number(lo, hi, clean), min_size=2, max_size=2))
    return good if clean else st.one_of(good, good, good, st.lists(FIN, max_size=3))


def point(lo: float = -250.0, hi: float = 250.0, clean: bool = False) -> st.SearchStrategy[Any]:
    """A point in mm, often inside the DexTAR's workspace, sometimes far outside."""
    inside = st.tuples(st.floats(-90, 90), st.floats(60, 150)).map(list)
    anywhere = st.lists(number(lo, hi, clean), min_size=2, max_size=2)
    if clean:
        return st.one_of(inside, inside, inside, anywhere)
    return st.one_of(inside, inside, inside, anywhere, st.lists(FIN, max_size=3), WRONG)


INTEGER = st.one_of(st.integers(-5, 5000), st.sampled_from([10**9, -(10**9)]), WRONG, FIN)
EXPRESSIONS = st.sampled_from([
    "40*cos(p)", "100 + 20*sin(p)", "30*p", "110 + 10/(p - 0.5)", "100 + log(p - 2)",
    "sqrt(-p)", "1e300*p*p", "p**p", "asin(2*p)", "tan(p*3.14159)", "", "p +", "__import__",
    "exp(1000*p)", "0*p", "100", "120 - 30*p**2", "abs(p)",
])


def _table(keys: dict[str, st.SearchStrategy[Any]], *, always: tuple[str, ...] = ()
           ) -> st.SearchStrategy[dict[str, Any]]:
    """A table with the keys ``always`` and a random subset of the others, and sometimes an
    unknown key."""
    names = sorted(k for k in keys if k not in always)

    @st.composite
    def build(draw: st.DrawFn) -> dict[str, Any]:
        chosen = draw(st.lists(st.sampled_from(names), unique=True, max_size=len(names))
                      ) if names else []
        d = {k: draw(keys[k]) for k in (*always, *sorted(chosen))}
        if draw(st.integers(0, 40)) == 17:  # (hypothesis favours 0: use another value)
            d["unknown_key"] = 1
        return d

    return build()


def tables(clean: bool) -> dict[str, st.SearchStrategy[dict[str, Any]]]:
    """A strategy per config table (``clean``: sensible values of the right types only)."""
    def pick(good: list[Any], bad: list[Any]) -> st.SearchStrategy[Any]:
        return st.sampled_from(good if clean else good + bad)

    integer = st.integers(10, 2000) if clean else INTEGER
    near = st.floats(0.8, 1.25)
    robot = st.fixed_dictionaries({"preset": st.just("dextar")}, optional={
        "l1": near.map(lambda f: 72 * f), "L1": near.map(lambda f: 87 * f),
        "d": near.map(lambda f: 60 * f), "working_mode": st.sampled_from(["+-", "pm", "--"]),
        "assembly_mode": st.just("up")}) if clean else _table({
                    "preset": pick(["dextar", "DexTAR"], ["unknown"]),
                    "l1": number(1, 200, clean), "l2": number(1, 200, clean), "L1": number(1, 200, clean),
                    "L2": number(1, 200, clean), "d": number(0.1, 300, clean),
                    "working_mode": pick(["++", "+-", "-+", "--", "pm", "mp", "mm", "pp", "+-",
                                          "+-"], ["x", ""]),
                    "assembly_mode": pick(["up", "down", "up"], ["sideways"])})
    paths = st.one_of(
        _table({"type": st.just("arc"), "radius": number(0.1, 200, clean), "center": point(clean=clean),
                "start_deg": number(-360, 360, clean), "end_deg": number(-360, 360, clean)}, always=("type",)),
        _table({"type": st.just("line"), "start": point(clean=clean), "end": point(clean=clean)},
               always=("type", "start", "end") if clean else ("type",)),
        _table({"type": st.just("spline"),
                "waypoints": st.lists(point(clean=clean), min_size=0, max_size=5)},
               always=("type", "waypoints") if clean else ("type",)),
        _table({"type": st.just("expression"), "x": EXPRESSIONS, "y": EXPRESSIONS,
                "p0": number(-2, 2, clean), "p1": number(-2, 3, clean)},
               always=("type", "x", "y") if clean else ("type",)),
        st.fixed_dictionaries({"type": pick(["arc"], ["circle", 3])}),
    )
    law = _table({"type": pick(["uniform", "min-jerk", "trapezoid", "optimal", "time-optimal"],
                               ["fast"]),
                  "duration": number(1e-3, 100, clean), "eta": number(1e-6, 1e6, clean),
                  "vmax": number(1, 1e5, clean), "amax": number(1, 1e6, clean),
                  "torque_limit": pair(1e-3, 100, clean), "speed_limit_deg_s": pair(1, 1e5, clean),
                  "grid": integer, **({} if clean else {"samples": INTEGER})})
    inertia = _table({"effector_mass": number(1e-3, 10, clean), "payload": number(0, 5, clean),
                      "proximal_mass": pair(0, 2, clean), "distal_mass": pair(0, 2, clean),
                      "proximal_com": pair(-10, 200, clean), "distal_com": pair(-10, 200, clean),
                      "proximal_inertia": pair(0, 1e4, clean), "distal_inertia": pair(0, 1e4, clean),
                      "rotor_inertia": pair(0, 1e4, clean)})
    friction = _table({"viscous": pair(0, 1, clean), "coulomb": pair(0, 1, clean),
                       "coulomb_speed_deg_s": number(1e-4, 100, clean)})
    gravity = _table({"vector": point(-2e4, 2e4, clean=clean)})
    control = _table({"natural_frequency_hz": number(0.1, 100, clean), "damping": number(0.05, 5, clean),
                      "mass_error": number(-0.5, 1, clean), "payload": number(0, 2, clean),
                      "torque_limit": number(1e-3, 10, clean),
                      "initial_error_deg": st.lists(number(-10, 10, clean), min_size=2,
                                                    max_size=2 if clean else 3)})
    paper = _table({"beta0_time": number(0, 1, clean), "fig7_distal_mass_ratio": number(0, 2, clean),
                    "fig7_lambda": number(0, 1, clean)})
    output = _table({"units": pick(["paper", "si"], ["imperial"]),
                     "samples": st.integers(2, 3000) if clean else st.one_of(
                         st.integers(2, 3000), INTEGER),
                     "figures": st.lists(pick(["fig3", "fig9", "workspace"], ["fig99"]),
                                         max_size=2),
                     "animation_frames": integer})

    return {"robot": robot, "path": paths, "law": law, "inertia": inertia,
            "friction": friction, "gravity": gravity, "control": control, "paper": paper,
            "output": output}


TABLES = {True: tables(True), False: tables(False)}


@st.composite
def configs(draw: st.DrawFn) -> dict[str, Any]:
    """A config: a random subset of the tables, each a random subset of its keys, and
    sometimes an unknown table or a value where a table belongs."""
    clean = draw(st.booleans())
    strategies = TABLES[clean]
    names = draw(st.sets(st.sampled_from(sorted(strategies)), max_size=len(strategies)))
    doc: dict[str, Any] = {n: draw(strategies[n]) for n in sorted(names)}
    extra = draw(st.integers(0, 60))
    if extra == 17 and not clean:
        doc["unknown_table"] = {"a": 1}
    elif extra == 23 and not clean:
        doc["law"] = 3
    return doc


COMMANDS = st.sampled_from(["plan", "torques", "plan", "torques", "export", "simulate"])


@st.composite
def kinematics_argv(draw: st.DrawFn) -> list[str]:
    """Command lines of ik, fk and workspace with odd numbers and options."""
    num = st.one_of(st.floats(-300, 300).map(lambda v: f"{v:g}"),
                    st.sampled_from(["nan", "inf", "-inf", "1e308", "x", "", "--", "-0"]))
    cmd = draw(st.sampled_from(["ik", "fk", "workspace"]))
    if cmd == "workspace":
        argv = ["workspace", "--resolution", draw(st.sampled_from(["2", "10", "40", "-3",
                                                                   "abc", "100000000"]))]
    else:
        argv = [cmd, draw(num), draw(num)]
    if cmd in ("ik", "workspace") and draw(st.booleans()):
        argv += ["--mode", draw(st.sampled_from(["+-", "--", "pm", "bad", "-+"]))]
    if cmd == "fk" and draw(st.booleans()):
        argv += ["--assembly", draw(st.sampled_from(["up", "down", "left"]))]
    if draw(st.booleans()):
        argv.append("--json")
    return argv


@st.composite
def programs(draw: st.DrawFn) -> dict[str, Any]:
    """A task file: motors, a start and a few moves of every type (sometimes bad values)."""
    clean = draw(st.booleans())
    pt = point(clean=clean)
    motors = {"peak_torque": draw(pair(0.05, 5.0, clean))}
    if draw(st.booleans()):
        motors["max_speed_rpm"] = draw(number(10, 600, clean))
        if draw(st.booleans()):
            motors["knee_speed_rpm"] = draw(number(1, 300, clean))
    moves = []
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["line", "arc", "dwell", "joint", "line", "arc"]
                                    + ([] if clean else ["jump"])))
        mv: dict[str, Any] = {"type": kind}
        if kind in ("line", "arc"):
            mv["to"] = draw(pt)
            if kind == "arc":
                if draw(st.booleans()):
                    mv["via"] = draw(pt)
                else:
                    mv["center"] = draw(pt)
                    mv["direction"] = draw(st.sampled_from(["ccw", "cw"]))
            if draw(st.booleans()):
                mv["blend"] = draw(number(0, 10, clean))
        elif kind == "dwell":
            mv["time"] = draw(number(0.01, 1, clean))
        elif kind == "joint":
            if draw(st.booleans()):
                mv["to"] = draw(pt)
                mv["working_mode"] = draw(st.sampled_from(["+-", "++", "-+", "--"]))
            else:
                mv["to_deg"] = [draw(number(-180, 360, clean)), draw(number(-180, 360, clean))]
        if draw(st.booleans()):
            law = draw(st.sampled_from(["min-jerk", "trapezoid", "optimal", "uniform"]))
            mv["law"] = law
            if law == "trapezoid":
                mv["vmax"], mv["amax"] = draw(number(10, 1e4, clean)), draw(number(10, 1e5, clean))
            mv["duration"] = draw(st.one_of(st.just("fit"), number(0.01, 3, clean)))
        moves.append(mv)
    doc: dict[str, Any] = {"motors": motors, "gravity": {"vector": [0.0, -9810.0]},
                           "inertia": {"effector_mass": 0.08, "proximal_mass": 0.03,
                                       "distal_mass": 0.02},
                           "program": {"start": draw(pt)}, "move": moves}
    return doc


#: Columns of a measured-motion file.
DATA_COLUMNS = ["t_s", "phi_rad", "psi_rad", "dphi_rad_s", "dpsi_rad_s", "tau1_Nm", "tau2_Nm"]
BAD_CELLS = st.sampled_from(["nan", "inf", "-inf", "1e308", "-1e308", "x", "", "1e-300",
                             "0", "-0"])


@st.composite
def motion_files(draw: st.DrawFn) -> tuple[str, list[str]]:
    """The text of a measured-motion CSV (a small motion of the DexTAR in working mode +-,
    sometimes damaged: a column dropped, bad cells, time reversed, duplicated or jittered,
    rows cut) and extra ``dextar identify`` options."""
    import numpy as np

    n = draw(st.sampled_from([4000, 4000, 2000, 300, 2, 0]))
    rate = draw(st.sampled_from([1000.0, 500.0]))
    t = np.arange(n) / rate
    w = 2 * np.pi * draw(st.sampled_from([0.3, 1.0, 2.0]))
    amp = draw(st.sampled_from([0.2, 0.05, 0.0, 3.0]))
    # (0, 100) mm in working mode +- is phi = 54.7, psi = 125.3 deg for the DexTAR
    q = np.stack([0.955 + amp * np.sin(w * t), 2.187 + amp * np.sin(1.7 * w * t + 1)], -1)
    dq = np.stack([amp * w * np.cos(w * t), 1.7 * amp * w * np.cos(1.7 * w * t + 1)], -1)
    tau = np.stack([0.1 * np.sin(w * t) + 0.05, 0.08 * np.cos(w * t)], -1)
    if draw(st.booleans()):
        t = {"reverse": t[::-1], "dup": np.where(np.arange(n) == n // 2, t - 1 / rate, t),
             "jitter": t + (np.arange(n) % 7 == 3) * 0.2 / rate}[
            draw(st.sampled_from(["reverse", "dup", "jitter"]))]
    rows = [[repr(float(v)) for v in r] for r in np.column_stack([t, q, dq, tau])]
    cols = list(DATA_COLUMNS)
    if draw(st.booleans()):
        drop = draw(st.sampled_from(cols))
        k = cols.index(drop)
        cols.pop(k)
        rows = [r[:k] + r[k + 1:] for r in rows]
    for _ in range(draw(st.integers(0, 2))):
        if rows:
            i = draw(st.integers(0, len(rows) - 1))
            j = draw(st.integers(0, len(cols) - 1))
            rows[i][j] = draw(BAD_CELLS)
    text = "\n".join([",".join(cols), *(",".join(r) for r in rows)]) + "\n"
    opts: list[str] = []
    if draw(st.booleans()):
        opts += ["--cutoff-hz", draw(st.sampled_from(["-1", "0", "1e-3", "0.5", "5", "249",
                                                      "250", "1e6", "nan", "inf"]))]
    return text, opts


# --- issue 28: metre-sized lengths, falling simulations, long runs with dry friction -------

@st.composite
def metre_configs(draw: st.DrawFn) -> dict[str, Any]:
    """A robot written in metres (the DexTAR's or a 120/180/100 robot's lengths / 1000,
    sometimes scaled), its path in metres or in mm, sometimes lengths at the bounds (1e-6 mm,
    1e9 mm) or beyond them."""
    k = draw(st.sampled_from([1e-3, 1e-3, 1e-3, 1e-6, 1e-9, 1e6, 1e7]))
    base = draw(st.sampled_from([(72.0, 87.0, 60.0), (120.0, 180.0, 100.0)]))
    l, L, d = (v * k for v in base)
    doc: dict[str, Any] = {"robot": {"l1": l, "l2": l, "L1": L, "L2": L, "d": d}}
    if draw(st.booleans()):  # the path in the same unit as the robot
        y = (l + L) * 0.7
        doc["path"] = draw(st.sampled_from([
            {"type": "line", "start": [-0.3 * d, y], "end": [0.3 * d, y]},
            {"type": "arc", "radius": 0.2 * (l + L), "center": [0.0, y], "start_deg": 0.0,
             "end_deg": 180.0}]))
    if draw(st.booleans()):
        doc["output"] = {"units": draw(st.sampled_from(["si", "paper"])), "samples": 101}
    if draw(st.booleans()):
        doc["gravity"] = {"vector": [0.0, -9810.0 * draw(st.sampled_from([1.0, 1e-3]))]}
    return doc


@st.composite
def falling_simulations(draw: st.DrawFn) -> dict[str, Any]:
    """A `simulate` config whose motors may be too weak to hold the robot (gravity, a
    payload, a torque limit from ample to far too low), with or without a tolerance."""
    doc: dict[str, Any] = {
        "robot": draw(st.sampled_from([
            {"preset": "dextar"},
            {"l1": 120.0, "l2": 120.0, "L1": 180.0, "L2": 180.0, "d": 100.0}])),
        "path": {"type": "arc", "radius": draw(st.sampled_from([20.0, 40.0, 60.0])),
                 "center": [0.0, draw(st.sampled_from([110.0, 150.0, 220.0]))],
                 "start_deg": 0.0, "end_deg": draw(st.sampled_from([90.0, 180.0, 720.0]))},
        "law": {"type": draw(st.sampled_from(["min-jerk", "optimal", "uniform"])),
                "duration": draw(st.sampled_from([0.3, 1.0, 3.0]))},
        "inertia": {"effector_mass": 0.1, "payload": draw(st.sampled_from([0.0, 0.3, 2.0]))},
        "friction": {"viscous": 0.005, "coulomb": draw(st.sampled_from([0.0, 0.02]))},
        "gravity": {"vector": [0.0, -9810.0]},
        "control": {"torque_limit": draw(st.sampled_from([0.01, 0.1, 0.3, 1.5, 10.0])),
                    "natural_frequency_hz": draw(st.sampled_from([2.0, 10.0, 50.0]))},
        "output": {"units": draw(st.sampled_from(["si", "paper"])), "samples": 201},
    }
    if draw(st.booleans()):
        doc["control"]["tolerance_mm"] = draw(st.sampled_from([1e-3, 0.5, 5.0, 1e3]))
    return doc


@st.composite
def dry_friction_runs(draw: st.DrawFn) -> dict[str, Any]:
    """A `dextar run` of a long or fast motion with dry friction (and gravity): seconds to
    a minute and a half, or many turns of an arc; no figures, few samples."""
    path = draw(st.sampled_from([
        {"type": "line", "start": [-60.0, 90.0], "end": [60.0, 115.0]},
        {"type": "arc", "radius": 30.0, "center": [0.0, 110.0], "start_deg": 0.0,
         "end_deg": 360.0 * draw(st.sampled_from([1, 5, 20]))},
        {"type": "spline", "waypoints": [[-50.0, 100.0], [0.0, 130.0], [50.0, 100.0]]}]))
    law = draw(st.sampled_from(["min-jerk", "uniform", "optimal", "trapezoid"]))
    return {
        "path": path,
        "law": {"type": law, "duration": draw(st.sampled_from([0.5, 2.0, 10.0, 30.0, 90.0])),
                **({"amax": 2000.0} if law == "trapezoid" and draw(st.booleans()) else {})},
        "inertia": {"effector_mass": draw(st.sampled_from([0.01, 0.05, 1.0]))},
        "friction": {"coulomb": draw(st.sampled_from([0.002, 0.02, 0.2])),
                     "viscous": draw(st.sampled_from([0.0, 1e-3])),
                     "coulomb_speed_deg_s": draw(st.sampled_from([0.01, 1.0]))},
        "gravity": {"vector": [0.0, draw(st.sampled_from([0.0, -9810.0]))]},
        "output": {"units": draw(st.sampled_from(["si", "paper"])), "samples": 201,
                   "figures": []},
    }


# --- review 28 finding 2: long motions with the figures and the animation on --------------

@st.composite
def long_animated_runs(draw: st.DrawFn) -> dict[str, Any]:
    """A `dextar run` of a motion from a minute to 1e9 s (about the 40-frame, 60 s-a-frame
    limit of a real-time animation, and far past it) with the animation and figures drawn:
    the animation must stay within its frames (a 1e9 s motion had asked for 1.7e7)."""
    law = draw(st.sampled_from(["min-jerk", "uniform", "optimal", "trapezoid"]))
    doc: dict[str, Any] = {
        "law": {"type": law,
                "duration": draw(st.sampled_from([60.0, 2400.0, 2460.0, 2461.0, 3600.0, 1e5,
                                                  1e7, 1e9]))},
        "output": {"units": draw(st.sampled_from(["si", "paper"])),
                   "samples": draw(st.sampled_from([101, 201, 1001])),
                   "animation_frames": draw(st.sampled_from([2, 41, 200]))},
    }
    figures = draw(st.sampled_from([None, ["animation"], ["animation", "fig4", "fig9"]]))
    if figures is not None:
        doc["output"]["figures"] = figures
    if draw(st.booleans()):
        doc["path"] = draw(st.sampled_from([
            {"type": "line", "start": [-60.0, 90.0], "end": [60.0, 115.0]},
            {"type": "arc", "radius": 30.0, "center": [0.0, 110.0], "start_deg": 0.0,
             "end_deg": 360.0 * draw(st.sampled_from([1, 20]))}]))
    if law == "trapezoid":
        doc["law"]["vmax"] = draw(st.sampled_from([1e-3, 1.0, 1000.0]))
        doc["law"]["amax"] = draw(st.sampled_from([1e-3, 1000.0]))
    if draw(st.booleans()):
        doc["friction"] = {"coulomb": 0.002}
        doc["gravity"] = {"vector": [0.0, -9810.0]}
    return doc


# --- issue 28: time scales ---------------------------------------------------------------

#: Factors a time column is multiplied by: seconds written as milliseconds, microseconds, or
#: as kiloseconds (the motion 1000 times faster).
TIME_SCALES = (1e-3, 1.0, 1e3, 1e6)


@st.composite
def time_scaled_motion_files(draw: st.DrawFn) -> tuple[str, list[str], float]:
    """A clean measured-motion CSV (a small motion of the DexTAR in working mode +-, 1000
    or 500 Hz) whose time column is multiplied by a factor of :data:`TIME_SCALES`; returns
    the text, extra ``dextar identify`` options and the factor."""
    import numpy as np

    n = draw(st.sampled_from([4000, 2000, 600]))
    rate = draw(st.sampled_from([1000.0, 500.0]))
    t = np.arange(n) / rate
    w = 2 * np.pi * draw(st.sampled_from([0.3, 1.0, 2.0]))
    amp = draw(st.sampled_from([0.2, 0.05, 0.0]))
    # (0, 100) mm in working mode +- is phi = 54.7, psi = 125.3 deg for the DexTAR
    q = np.stack([0.955 + amp * np.sin(w * t), 2.187 + amp * np.sin(1.7 * w * t + 1)], -1)
    tau = np.stack([0.1 * np.sin(w * t) + 0.05, 0.08 * np.cos(w * t)], -1)
    factor = draw(st.sampled_from(TIME_SCALES))
    rows = np.column_stack([factor * t, q, tau])
    text = "\n".join(["t_s,phi_rad,psi_rad,tau1_Nm,tau2_Nm",
                      *(",".join(repr(float(v)) for v in r) for r in rows)]) + "\n"
    opts = ["--cutoff-hz", "5"] if draw(st.integers(0, 3)) == 1 else []
    return text, opts, factor


# --- issue 32: counterweights on the proximal rods ------------------------------------------

@st.composite
def counterweight_configs(draw: st.DrawFn) -> dict[str, Any]:
    """A config whose proximal rods carry counterweights: masses from none to far heavier than
    the robot, distances from on the axis to far beyond the rods, with or without their own
    inertia, sometimes a mass without its distance or out of range (refused by name); with
    gravity, friction and either unit system."""
    mass = draw(st.sampled_from([0.0, 1e-6, 0.02, 0.5, 50.0, [0.1, 0.0], [0.0, 3.0], -0.1]))
    inertia: dict[str, Any] = {"effector_mass": draw(st.sampled_from([0.05, 1.0])),
                               "counterweight_mass": mass}
    if draw(st.integers(0, 9)) > 0:  # mostly with a distance
        inertia["counterweight_distance"] = draw(st.sampled_from(
            [0.0, 1e-6, 5.0, 30.0, 500.0, 1e6, [10.0, 40.0], -1.0]))
    if draw(st.booleans()):
        inertia["counterweight_inertia"] = draw(st.sampled_from([0.0, 10.0, 1e4, [5.0, 0.0]]))
    return {
        "inertia": inertia,
        "path": {"type": "arc", "radius": 30.0, "center": [0.0, 110.0], "start_deg": 0.0,
                 "end_deg": draw(st.sampled_from([90.0, 180.0]))},
        "law": {"type": draw(st.sampled_from(["min-jerk", "optimal"])),
                "duration": draw(st.sampled_from([0.3, 2.0]))},
        "friction": {"coulomb": draw(st.sampled_from([0.0, 0.02])), "viscous": 1e-3},
        "gravity": {"vector": [0.0, draw(st.sampled_from([0.0, -9810.0]))]},
        "output": {"units": draw(st.sampled_from(["si", "paper"])), "samples": 101},
    }
