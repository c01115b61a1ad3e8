"""The program's operating-points figure draws what can be seen: one marker per occupied
cell of the plot, not one per setpoint (a new user's 942 s program at 1 kHz had made its SVG
276 MB)."""

from types import SimpleNamespace

import numpy as np

from dextar.output.figures import svg_bytes
from dextar.output.program import POINT_CELLS, distinct_points, operating_points_figure


def cells(x, y, idx, n=POINT_CELLS):
    def c(v):
        span = np.ptp(v)
        return np.minimum(((v - v.min()) / span * n).astype(int), n - 1)

    return set(zip(c(x)[idx].tolist(), c(y)[idx].tolist(), strict=True))


def test_one_point_per_occupied_cell_every_cell_kept():
    rng = np.random.default_rng(2)
    t = np.linspace(0.0, 40.0, 400_001)
    x = np.abs(np.sin(t)) * 3 + rng.normal(0, 0.01, t.size)
    y = np.abs(np.cos(1.3 * t)) * 0.8 + rng.normal(0, 0.003, t.size)
    idx = distinct_points(x, y)
    everything = np.arange(t.size)
    assert cells(x, y, idx) == cells(x, y, everything)  # (the extremes' cells among them)
    assert len(idx) == len(cells(x, y, idx)) < t.size // 4  # (measured: 84,379 of 400,001)
    assert np.all(np.diff(idx) > 0)
    assert len(distinct_points(np.ones(5), np.zeros(5))) == 1
    assert len(distinct_points(np.zeros(0), np.zeros(0))) == 0


def test_the_operating_points_svg_stays_small_however_many_setpoints():
    n = 200_000  # (200 s at 1 kHz)
    t = np.linspace(0.0, 200.0, n)
    dq = np.stack([np.sin(t), np.cos(0.7 * t)], axis=1) * 5.0
    tau = np.stack([np.cos(t), np.sin(0.7 * t) + 0.3], axis=1)
    res = SimpleNamespace(dq=dq, tau=tau, motors=None, rms_limit=None)
    motor = SimpleNamespace(peak_torque_Nm=1.3, rms_torque_Nm=0.8)
    fig = operating_points_figure(res, SimpleNamespace(motors=(motor, motor)))
    drawn = [len(ax.lines[0].get_xdata()) for ax in fig.axes]
    assert all(0 < k < n // 10 for k in drawn), drawn  # (measured: 1190 and 2115)
    # (measured: 0.54 MB; one marker per setpoint: 58.6 MB, 4.4 s)
    assert len(svg_bytes(fig)) < 2e6
