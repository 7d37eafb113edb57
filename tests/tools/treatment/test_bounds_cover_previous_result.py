"""Variable bounds widened to cover a previous result used as the initial guess
(nmsm.tools.treatment.tool._covering): the tracked data's bounds stay where the result lies
inside them; where it leaves them they move past it by COVER_MARGIN of the widened range."""

from __future__ import annotations

import numpy as np

from nmsm.tools.treatment.tool import COVER_MARGIN, _covering


def test_bounds_move_only_where_the_result_leaves_them() -> None:
    lower, upper = np.array([-1.0, -1.0, -1.0]), np.array([1.0, 1.0, 1.0])
    values = np.array([[0.5, -3.0, 0.0],
                       [-0.5, 0.0, 2.0]])  # column 0 inside; column 1 below; column 2 above
    lo, hi = _covering(lower, upper, values)
    np.testing.assert_allclose(lo, [-1.0, -3.0 - COVER_MARGIN * 4.0, -1.0])
    np.testing.assert_allclose(hi, [1.0, 1.0, 2.0 + COVER_MARGIN * 3.0])
    assert np.all(values > lo) and np.all(values < hi)
