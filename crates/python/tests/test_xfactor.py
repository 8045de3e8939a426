"""xfactor: vectorised, equal to `hydrocyl xfactor`, errors as the CLI's."""

import numpy as np
import pytest

import hydrocyl
from conftest import run_cli


def test_xfactor_equals_the_cli(cli):
    travel = np.linspace(-1.5, 1.5, 31)
    x = hydrocyl.xfactor(1.9707, travel)
    _, out, _ = run_cli(cli, "xfactor", "--gamma", "1.9707", "--travel", ",".join(repr(float(v)) for v in travel))
    expected = np.array([float(line.split()[1]) for line in out.splitlines()])
    np.testing.assert_array_equal(x, expected)
    assert x[0] == pytest.approx(1.9707**2) and x[-1] == 1.0  # outside the underlap


def test_xfactor_keeps_the_shape_and_takes_lists():
    grid = np.linspace(-1, 1, 12).reshape(3, 4)
    assert hydrocyl.xfactor(2.0, grid).shape == (3, 4)
    np.testing.assert_array_equal(hydrocyl.xfactor(2.0, [0.0, 0.5]), hydrocyl.xfactor(2.0, np.array([0.0, 0.5])))


def test_xfactor_errors(cli):
    with pytest.raises(ValueError) as e:
        hydrocyl.xfactor(0.5, [0.0])
    _, _, line = run_cli(cli, "xfactor", "--gamma", "0.5", "--travel", "0", expect_ok=False)
    assert str(e.value) == line
    with pytest.raises(ValueError, match=r"travel\[2\]: spool travel = NaN"):
        hydrocyl.xfactor(2.0, [0.0, 0.1, np.nan])
