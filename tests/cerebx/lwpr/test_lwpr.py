"""LWPR known answers: the reference library's cross benchmark, a 1-D function, RF creation by the
activation threshold, distance-metric adaptation, storage growth and input checks."""

import numpy as np
import pytest

from cerebx.lwpr import LWPR, LWPRParams
from cerebx.lwpr.bench import cross


def test_cross_function_matches_reference_library():
    """example_c/cross.c protocol (docs/provenance.md#lwpr-benchmark): reference nMSE 0.021-0.025 with 53-61 RFs."""
    rng = np.random.default_rng(1)
    model = LWPR(2, 1, init_D=50.0, init_alpha=250.0, w_gen=0.2)
    for _ in range(20):
        xs = rng.uniform(-1, 1, (1000, 2))
        ys = cross(xs) + rng.uniform(-0.05, 0.05, 1000)
        for x, y in zip(xs, ys):
            model.update(x, [y])
    grid = np.linspace(-1, 1, 41)
    test = np.array([[a, b] for a in grid for b in grid])
    pred = np.array([model.predict(x)[0] for x in test])
    nmse = np.mean((pred - cross(test)) ** 2) / np.var(cross(test))
    assert 0.01 < nmse < 0.035
    assert 45 <= model.n_receptive_fields[0] <= 70


def test_one_dimensional_function():
    rng = np.random.default_rng(0)
    model = LWPR(1, 1)
    f = lambda x: np.sin(3 * x) + 0.5 * x  # noqa: E731
    for x in rng.uniform(-1, 1, 5000):
        model.update([x], [f(x) + rng.normal(0, 0.05)])
    test = np.linspace(-0.95, 0.95, 200)
    pred = np.array([model.predict([x])[0] for x in test])
    assert np.mean((pred - f(test)) ** 2) / np.var(f(test)) < 0.01
    assert 3 <= model.n_receptive_fields[0] <= 30


def test_receptive_field_created_only_below_w_gen():
    """Gaussian RF with D = 25: activation at distance d is exp(-12.5 d^2); w_gen = 0.1 is crossed at
    d = sqrt(2 ln 10 / 25) = 0.429."""
    model = LWPR(1, 1, update_D=False)
    model.update([0.0], [1.0])
    assert model.n_receptive_fields == [1]
    model.update([0.40], [1.0])  # activation 0.135 > w_gen: no new RF
    assert model.n_receptive_fields == [1]
    model.update([0.45], [1.0])  # 0.079 <= w_gen: a new RF centred there
    assert model.n_receptive_fields == [2]
    np.testing.assert_allclose(model.centres(0)[:, 0], [0.0, 0.45])
    np.testing.assert_allclose(model.activations([0.45])[0], [np.exp(-12.5 * 0.45**2), 1.0])


def test_distance_metric_adapts_only_when_enabled():
    rng = np.random.default_rng(3)
    xs = rng.uniform(-1, 1, (3000, 2))
    ys = cross(xs)
    fixed, adaptive = LWPR(2, 1, update_D=False), LWPR(2, 1, update_D=True)
    for x, y in zip(xs, ys):
        fixed.update(x, [y])
        adaptive.update(x, [y])
    init = 25.0 * np.eye(2)
    for k in range(fixed.n_receptive_fields[0]):
        np.testing.assert_array_equal(fixed.distance_metric(0, k), init)
    changed = [not np.allclose(adaptive.distance_metric(0, k), init) for k in range(adaptive.n_receptive_fields[0])]
    assert sum(changed) >= adaptive.n_receptive_fields[0] // 2
    D0 = adaptive.distance_metric(0, 0)
    assert D0[0, 1] == 0.0 and D0[1, 0] == 0.0  # diag_only keeps D diagonal


def test_storage_grows_and_outputs_are_independent():
    # (2 inputs, the second constant: the 2-in/2-out shape test_update_many compiles; numba compiles ~20 s a shape)
    model = LWPR(2, 2, init_D=400.0, initial_capacity=2)
    for _ in range(5):
        for x in np.linspace(-1, 1, 41):
            model.update([x, 0.5], [x, -2 * x])
    assert model.n_receptive_fields[0] > 2 and model.n_receptive_fields[0] == model.n_receptive_fields[1]
    y = model.predict([0.3, 0.5])
    assert y[0] == pytest.approx(0.3, abs=0.05) and y[1] == pytest.approx(-0.6, abs=0.1)
    _, acts = model.predict_with_activations([0.3, 0.5])
    assert len(acts) == 2 and acts[0].shape == (model.n_receptive_fields[0],) and acts[0].max() > 0.5


def test_normalisation_and_bad_input():
    model = LWPR(1, 1, norm_in=10.0, norm_out=100.0, init_D=25.0)
    for x in np.linspace(-10, 10, 400):
        model.update([x], [50.0 * x])
    assert model.predict([5.0])[0] == pytest.approx(250.0, rel=0.05)
    with pytest.raises(ValueError, match="input needs 1"):
        model.predict([1.0, 2.0])
    with pytest.raises(ValueError, match="norm_in: needs 1 or 2"):
        LWPR(2, 1, norm_in=(1.0, 2.0, 3.0))
    with pytest.raises(ValueError):
        LWPRParams(w_gen=1.5)


def test_update_many_and_predict_many_equal_the_per_sample_calls():
    """One kernel call for a whole stream learns bit for bit what ``update`` learns sample by sample,
    also when the RF storage has to grow on the way (initial capacity 2)."""
    rng = np.random.default_rng(5)
    xs = rng.uniform(-1, 1, (2000, 2))
    ys = np.stack([cross(xs), -cross(xs)], axis=1) + rng.uniform(-0.05, 0.05, (2000, 2))
    one, many = (LWPR(2, 2, init_D=50.0, init_alpha=250.0, w_gen=0.2, initial_capacity=2) for _ in range(2))
    yp_one = np.array([one.update(x, y) for x, y in zip(xs, ys)])
    yp_many = many.update_many(xs, ys)
    assert many.n_receptive_fields == one.n_receptive_fields and one.n_receptive_fields[0] > 8
    np.testing.assert_array_equal(yp_many, yp_one)
    test = rng.uniform(-1, 1, (50, 2))
    np.testing.assert_array_equal(many.predict_many(test), np.array([one.predict(x) for x in test]))
    assert one.n_updates == many.n_updates == 2000


def test_state_round_trip_predicts_the_same():
    rng = np.random.default_rng(6)
    model = LWPR(2, 1, init_D=50.0, w_gen=0.2)
    model.update_many(rng.uniform(-1, 1, (500, 2)), rng.uniform(0, 1, (500, 1)))
    copy = LWPR(2, 1, init_D=50.0, w_gen=0.2)
    copy.load(model.state())
    test = rng.uniform(-1, 1, (20, 2))
    np.testing.assert_array_equal(copy.predict_many(test), model.predict_many(test))
    assert copy.n_created == model.n_created


def test_far_distance_bounds_the_skipped_activations():
    """RFs farther than far_distance(w) are skipped without evaluating the kernel: their activation must
    lie below w (Gaussian exp(-q/2), BiSquare (1 - q/4)^2)."""
    from cerebx.lwpr.kernels import far_distance

    for w in (0.001, 0.02, 0.5):
        q = far_distance(w, bisquare=False)
        assert q == pytest.approx(-2 * np.log(w), rel=1e-8) and np.exp(-q / 2) < w
        q = far_distance(w, bisquare=True)
        assert q == pytest.approx(4 * (1 - np.sqrt(w)), rel=1e-8) and (1 - q / 4) ** 2 < w
    assert far_distance(0.0, bisquare=False) == np.inf


def test_any_array_like_input_learns_what_float64_rows_learn():
    """``update`` and ``predict`` take the caller's float64 C-contiguous rows as they are and convert anything
    else (lists, float32, read-only, strided, 2-D single rows) to the same values: the same model bit for bit.
    Two models of one shape share their compiled kernels but not their state."""
    rng = np.random.default_rng(8)
    xs = rng.uniform(-1, 1, (400, 2)).astype(np.float32).astype(np.float64)  # exact in float32 too
    ys = cross(xs)[:, None]
    ref, other = LWPR(2, 1, initial_capacity=2), LWPR(2, 1, initial_capacity=2)
    for x, y in zip(xs, ys):
        ref.update(x, y)
    frozen = xs.copy()
    frozen.flags.writeable = False
    strided = np.asfortranarray(xs)  # its rows are not contiguous
    for t, (x, y) in enumerate(zip(xs, ys)):
        form = t % 5
        if form == 0:
            other.update(list(x), float(y[0]))
        elif form == 1:
            other.update(x.astype(np.float32).reshape(1, 2), y)
        elif form == 2:
            other.update(frozen[t], y)
        elif form == 3:
            other.update(strided[t], y.reshape(1, 1))
        else:
            other.update(x, y)
    assert other.n_receptive_fields == ref.n_receptive_fields and ref.n_receptive_fields[0] > 2
    for x in rng.uniform(-1, 1, (20, 2)):
        want = ref.predict(x)
        for form in (list(x), x.reshape(1, 2), np.asfortranarray(np.stack([x, x]))[0], x):
            np.testing.assert_array_equal(other.predict(form), want)
    assert ref.predict(xs[0]) is not ref.predict(xs[0])  # a new array each call


def test_a_pickled_model_learns_on_as_the_original():
    """Checkpoints pickle the controllers, LWPR included: the unpickled model (and one pickled by earlier code,
    whose ``__dict__`` held the RF arrays as ``_store`` beside a buffer without the pred region) has its own
    buffer and learns on bit for bit as the original does."""
    import pickle

    from cerebx.lwpr import kernels as K

    rng = np.random.default_rng(9)
    xs = rng.uniform(-1, 1, (1500, 2))
    ys = cross(xs)[:, None]
    model = LWPR(2, 1, initial_capacity=2)
    model.update_many(xs[:500], ys[:500])
    old = {k: v for k, v in model.__dict__.items() if k not in ("_addr", "_pred", "_update", "_predict")}
    old["_store"] = K.Store(*(a.copy() for a in model._store))
    old["_buf"] = np.full(K.regions(2, 1, model._store.mat.shape[1])[-1] - 1, np.nan)  # the old layout's size
    earlier = LWPR.__new__(LWPR)
    earlier.__setstate__(pickle.loads(pickle.dumps(old)))
    copies = [pickle.loads(pickle.dumps(model)), earlier]
    for x, y in zip(xs[500:], ys[500:]):  # the storage grows on the way
        want = model.update(x, y)
        for c in copies:
            np.testing.assert_array_equal(c.update(x, y), want)
    test = rng.uniform(-1, 1, (30, 2))
    for c in copies:
        assert c.n_receptive_fields == model.n_receptive_fields and c._buf is not model._buf
        np.testing.assert_array_equal(c.predict_many(test), model.predict_many(test))
