"""HermiteTable, the arc-length tables' interpolant, against scipy's CubicHermiteSpline (the
library it stands in for on the paths, where scipy.interpolate would cost half a second to
import)."""

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from dextar.paths.base import HermiteTable


@pytest.mark.parametrize("n", [2, 3, 10, 4097])
def test_hermite_table_is_scipys_cubic_hermite_spline(n):
    """Inside the knots, at them and beyond both ends. Measured: equal to the last bit on
    this machine (the same coefficients and sum); bound 1e-14 of the values' scale, as another
    build of scipy may fuse its multiply-adds. A slope changed by 1e-6 is seen (2.6e-10 on the finest table)."""
    rng = np.random.default_rng(n)
    x = np.sort(rng.uniform(0.0, 5.0, n))
    y, m = rng.normal(size=n), rng.normal(size=n)
    xi = np.concatenate([rng.uniform(x[0] - 0.3, x[-1] + 0.3, 20000), x])
    ref = CubicHermiteSpline(x, y, m)(xi)
    scale = np.abs(ref).max()
    np.testing.assert_allclose(HermiteTable(x, y, m)(xi), ref, rtol=0, atol=1e-14 * scale)
    np.testing.assert_allclose(HermiteTable(x, y, m)(x), y, rtol=0, atol=1e-14 * scale)
    bent = m.copy()
    bent[n // 2] += 1e-6
    assert np.abs(HermiteTable(x, y, bent)(xi) - ref).max() > 1e-12
    assert HermiteTable(x, y, m)(xi.reshape(-1, 1)).shape == (len(xi), 1)


def test_knots_that_do_not_rise_are_refused():
    from dextar.errors import ParameterError

    for x in ([0.0, 1.0, 1.0, 2.0], [0.0, 2.0, 1.0], [0.0], [0.0, float("nan")]):
        with pytest.raises(ParameterError, match="rising knots"):
            HermiteTable(np.array(x), np.zeros(len(x)), np.zeros(len(x)))
