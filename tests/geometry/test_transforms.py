"""Unit vectors: the one normaliser every asset builder uses (``generator.geometry.unit``)."""

import numpy as np

from generator.geometry import unit


def test_unit_vectors_have_length_one_and_keep_their_direction():
    v = np.array([[3.0, 4.0, 0.0], [0.0, -2.0, 0.0], [1e-6, 0.0, 1e-6]])
    u = unit(v)
    np.testing.assert_allclose(np.linalg.norm(u, axis=-1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(u[0], [0.6, 0.8, 0.0])
    assert np.all(np.sign(u) == np.sign(v))


def test_a_zero_vector_stays_zero_instead_of_nan():
    u = unit(np.zeros((2, 3)))
    assert np.all(u == 0.0)


def test_float32_stays_float32_and_integers_become_float64():
    assert unit(np.ones(3, np.float32)).dtype == np.float32
    u = unit((0, 0, 2))
    assert u.dtype == np.float64 and u.tolist() == [0.0, 0.0, 1.0]


def test_cross_is_numpys_bit_for_bit():
    """``cross`` (numpy's products and differences without its axis handling) gives np.cross's bytes."""
    from generator.geometry import cross

    g = np.random.default_rng(3)
    a, b = g.normal(size=(200, 3)) * 1e3, g.normal(size=(200, 3))
    for x, y in ((a, b), (a[0], b[0]), (a, b[5]), (a[:, None], b[None, :7])):
        assert np.array_equal(cross(x, y), np.cross(x, y))
        assert cross(x, y).dtype == np.cross(x, y).dtype


def test_unit_is_the_norm_division_bit_for_bit():
    g = np.random.default_rng(4)
    v = g.normal(size=(300, 3)) * g.uniform(1e-3, 1e3, (300, 1))
    want = v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-12)
    assert np.array_equal(unit(v), want)
    assert np.array_equal(unit(v[0]), want[0])


def test_cross_falls_back_to_numpy_off_3_vectors():
    from generator.geometry import cross

    assert np.array_equal(cross(np.array([[1.0, 2.0]]), np.array([[3.0, 5.0]])), np.cross([[1.0, 2.0]], [[3.0, 5.0]]))
    assert np.array_equal(cross([1, 2, 3], [4, 5, 7]), np.cross([1, 2, 3], [4, 5, 7]))
