"""The writer's bulk reals (issue 22: "%.17g" built by array arithmetic) are the text C's
printf gives, byte for byte, and read back exactly: random magnitudes from 1e-6 to 1e18
of both signs, next to every power of ten, halves and near-integers, and the values the
array path hands to format_real (zero, integers, tiny, huge) at random places."""
import numpy as np

from bladesmith.iges.writer import SHORTEST_REPR_SIZE, _reals, format_real


def printf_join(a):
    out = []
    for x in a.tolist():
        m = abs(x)
        special = x == int(x) or m < 1e-4 or m >= 1e17 if np.isfinite(x) else True
        out.append(format_real(x) if special else "%.17g" % x)
    return ",".join(out)


def cases():
    rng = np.random.default_rng(2022)
    p = 10.0 ** np.arange(-5, 19)
    yield np.concatenate([
        rng.uniform(-3, 3, 20000), rng.normal(size=5000) * 1e-3,
        10 ** rng.uniform(-6, 18, 20000) * rng.choice([-1, 1], 20000),
        np.nextafter(p, 0), np.nextafter(p, np.inf), -np.nextafter(p, 0), p * (1 + 2**-52),
        0.5 ** np.arange(1, 40), 1 + 2.0 ** -np.arange(1, 53), 7 - 2.0 ** -np.arange(1, 51),
        [0.0, -0.0, 1.0, -2.0, 1e20, 1e-300, 5e-324, 123456.0, 0.1, -0.5, 9.999999999999999e16],
    ])
    yield rng.normal(size=SHORTEST_REPR_SIZE + 1)  # the smallest bulk array
    yield np.abs(rng.normal(size=5000)) + 1e-3  # no special values at all
    yield np.arange(1.0, 400.0)  # only special values (integers)
    yield 1e-5 * np.arange(1, 400)  # only special values (exponent form)


def test_bulk_reals_are_printf_17g_and_round_trip():
    rng = np.random.default_rng(7)
    for a in cases():
        a = a.copy()
        rng.shuffle(a)
        text = _reals(a)
        assert text == printf_join(a)
        back = np.array([float(s.replace("E", "e")) for s in text.split(",")])
        assert np.array_equal(back, a) and np.array_equal(np.signbit(back), np.signbit(a))
        assert all("." in s for s in text.split(","))
