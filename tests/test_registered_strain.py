"""benchmarks/registered_strain.py: the kinematic strain increment of an affine fit, and its page."""
import json
import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))


def _lattice(n=12, dx=1.0):
    g = np.arange(n, dtype=float) * dx
    return np.stack(np.meshgrid(g, g), axis=-1).reshape(-1, 2)


def test_strain_increment_of_simple_shear_translation_and_rotation():
    """A lattice sheared by a small gamma: every particle gets gamma / sqrt(3) (the von Mises measure of simple
    shear); moved rigidly it gets 0 (a small rotation: only its second-order stretch)."""
    import registered_strain as rs
    from refsph.kernels import get_kernel
    X, k, h = _lattice(), get_kernel("wendland"), 1.3
    g = 1e-3
    y = X + g * np.stack([X[:, 1], 0 * X[:, 1]], axis=1)
    assert np.allclose(rs.strain_increment(X, y, h, k), g / math.sqrt(3.0), rtol=1e-9)
    assert np.allclose(rs.strain_increment(X, X + [0.3, -0.2], h, k), 0.0, atol=1e-12)
    t = 1e-4
    R = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    assert rs.strain_increment(X, X @ R.T, h, k).max() < t**2


def test_page_is_made_from_the_json():
    import registered_strain as rs
    rows = json.loads((ROOT / "benchmarks" / "registered_strain.json").read_text())
    assert rs.report(rows) == (ROOT / "benchmarks" / "registered_strain_report.md").read_text()
