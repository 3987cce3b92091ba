"""The prefilter's own Butterworth design and zero-phase filtering against scipy.signal."""

import numpy as np
import pytest

from shipid.data.butterworth import butter_lowpass_sos
from shipid.data.butterworth import sosfiltfilt as own_sosfiltfilt


@pytest.mark.parametrize("order", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("cutoff, fs", [(0.5, 5.0), (1.25, 10.0), (0.01, 2.0), (2.4, 5.0)])
def test_design_and_filtering_match_scipy(order, cutoff, fs):
    # Imported here: at the top, each test worker paid scipy.signal's 0.6 s while collecting,
    # though one runs these tests (shipid itself never imports it).
    from scipy.signal import butter, sosfiltfilt

    ref = butter(order, cutoff, fs=fs, output="sos")
    sos = butter_lowpass_sos(order, cutoff, fs)
    # the same cascade: equal frequency response at every frequency
    w = np.linspace(0, np.pi, 50)
    z = np.exp(1j * w)

    def response(s):
        return np.prod([(c[0] + c[1] / z + c[2] / z**2) / (c[3] + c[4] / z + c[5] / z**2)
                        for c in s], axis=0)  # fmt: skip

    np.testing.assert_allclose(response(sos), response(ref), rtol=1e-9, atol=1e-12)
    rng = np.random.default_rng(order)
    for n in (ref.shape[0] * 6 + 4, 700):  # just longer than the padding, and long
        x = np.cumsum(rng.normal(size=n)) + rng.normal(size=n)
        expected = sosfiltfilt(ref, x)
        np.testing.assert_allclose(own_sosfiltfilt(sos, x), expected,
                                   atol=1e-11 * np.max(np.abs(expected)))  # fmt: skip


def test_bad_designs_and_short_signals_are_refused():
    with pytest.raises(ValueError, match="Nyquist"):
        butter_lowpass_sos(2, 2.5, 5.0)
    with pytest.raises(ValueError, match="order"):
        butter_lowpass_sos(0, 1.0, 5.0)
    with pytest.raises(ValueError, match="more than 9 samples"):
        own_sosfiltfilt(butter_lowpass_sos(2, 1.0, 5.0), np.ones(9))
