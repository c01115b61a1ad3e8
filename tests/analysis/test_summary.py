"""A run's law summary from the law's own report and its config keys, for every law."""

import pytest

from dextar.analysis.summary import law_summary
from dextar.config import scenario_from_dict


@pytest.mark.parametrize("law, keys", [
    ({"type": "optimal", "duration": 1.0, "eta": 0.1},
     {"eta", "eta_s2_per_kg", "ode_residual", "nodes"}),
    ({"type": "trapezoid", "vmax": 400.0, "amax": 4000.0},
     {"vmax", "amax", "cruise_speed", "vmax_mm_s", "amax_mm_s2"}),
    ({"type": "time-optimal", "torque_limit": 2.0, "grid": 100},
     {"torque_limit_Nm", "grid", "max_torque_ratio_check_samples", "max_torque_ratio"}),
    ({"type": "min-jerk", "duration": 0.5}, set()),
])
def test_law_summary_has_the_laws_own_quantities(law, keys):
    from dextar.analysis import analyze

    sc = scenario_from_dict({"law": law, "output": {"units": "si", "samples": 101},
                             "inertia": {"effector_mass": 0.1}})
    an = analyze(sc.inputs(), sc.law())
    s = law_summary(sc.inputs(), an.law, an)
    base = {"type", "duration", "duration_s", "status", "success", "message"}
    assert set(s) == base | keys
    if law["type"] == "time-optimal":
        assert s["torque_limit_Nm"] == [2.0, 2.0] and s["max_torque_ratio"] <= 1.001
    if law["type"] == "optimal":
        assert s["eta_s2_per_kg"] == 0.1
