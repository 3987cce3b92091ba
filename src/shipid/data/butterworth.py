"""Zero-phase Butterworth low-pass filtering without importing ``scipy.signal``.

``scipy.signal`` takes 0.9 s to import (it parses some 800 docstrings), as long as the whole of
an ``identify`` run. The few pieces the prefilter needs are written here after the textbook
and checked against ``scipy.signal.butter`` and ``sosfiltfilt`` in the tests:

* design: the analog Butterworth prototype's poles exp(iπ(2k + n − 1)/(2n)), k = 1…n, scaled to
  the prewarped cut-off 2 f_s tan(π f_c / f_s) and mapped by the bilinear transform
  z = (2 f_s + s)/(2 f_s − s); all zeros at z = −1; unit gain at DC; conjugate pairs as
  second-order sections (a first-order one for an odd order);
* filtering: each section in transposed direct form II, forward then backward, on the signal
  extended by odd reflection at both ends, from each section's steady state (Gustafsson's
  initial conditions as ``sosfiltfilt`` with its default padding).
"""

from __future__ import annotations

import math

import numba
import numpy as np


def butter_lowpass_sos(order: int, cutoff_hz: float, fs: float) -> np.ndarray:
    """Second-order sections (n_sections, 6) [b0 b1 b2 1 a1 a2] of a digital Butterworth
    low-pass of ``order`` with its −3 dB point at ``cutoff_hz`` for sampling rate ``fs``."""
    if order < 1:
        raise ValueError(f"filter order must be ≥ 1, got {order}")
    if not 0 < cutoff_hz < fs / 2:
        raise ValueError(f"cut-off must be between 0 and the Nyquist frequency {fs / 2:g} Hz")
    k2 = 2.0 * fs
    warped = k2 * math.tan(math.pi * cutoff_hz / fs)
    poles = [warped * np.exp(1j * math.pi * (2 * k + order - 1) / (2 * order))
             for k in range(1, order + 1)]  # fmt: skip
    digital = [(k2 + p) / (k2 - p) for p in poles]
    upper = sorted((z for z in digital if z.imag > 1e-14), key=lambda z: abs(z))
    real = [z.real for z in digital if abs(z.imag) <= 1e-14]
    sections = []
    for z in real:  # first-order section: zero at −1, pole at z
        sections.append([1.0, 1.0, 0.0, 1.0, -z, 0.0])
    for z in upper:  # a conjugate pair: zeros at −1 (double)
        sections.append([1.0, 2.0, 1.0, 1.0, -2.0 * z.real, abs(z) ** 2])
    sos = np.array(sections)
    # Unit gain at DC (z = 1), given to the first section as ``butter`` does.
    dc = np.prod(sos[:, 3:].sum(axis=1) / sos[:, :3].sum(axis=1))
    sos[0, :3] *= dc
    return sos


def _section_steady_state(section: np.ndarray) -> np.ndarray:
    """The delay states of one section at rest under a unit constant input (``lfilter_zi``)."""
    b0, b1, b2, _, a1, a2 = section
    minus_companion = np.array([[1.0 + a1, -1.0], [a2, 1.0]])
    return np.linalg.solve(minus_companion, np.array([b1 - a1 * b0, b2 - a2 * b0]))


def sos_steady_state(sos: np.ndarray) -> np.ndarray:
    """(n_sections, 2) initial states for a unit step at rest through the cascade."""
    zi = np.empty((sos.shape[0], 2))
    scale = 1.0
    for i, section in enumerate(sos):
        zi[i] = scale * _section_steady_state(section)
        scale *= section[:3].sum() / section[3:].sum()
    return zi


@numba.njit(cache=True)
def _sosfilt(sos: np.ndarray, x: np.ndarray, zi: np.ndarray) -> np.ndarray:
    y = x.copy()
    for s in range(sos.shape[0]):
        b0, b1, b2, a1, a2 = sos[s, 0], sos[s, 1], sos[s, 2], sos[s, 4], sos[s, 5]
        z0, z1 = zi[s, 0], zi[s, 1]
        for k in range(y.shape[0]):
            xk = y[k]
            yk = b0 * xk + z0
            z0 = b1 * xk - a1 * yk + z1
            z1 = b2 * xk - a2 * yk
            y[k] = yk
    return y


def sosfiltfilt(sos: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Zero-phase filtering of ``x`` by the cascade ``sos`` (forward, then backward)."""
    x = np.asarray(x, dtype=np.float64)
    trivial = min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    pad = 3 * (2 * sos.shape[0] + 1 - trivial)
    if x.shape[0] <= pad:
        raise ValueError(f"the signal needs more than {pad} samples for this filter")
    ext = np.concatenate([2 * x[0] - x[pad:0:-1], x, 2 * x[-1] - x[-2:-pad - 2:-1]])
    zi = sos_steady_state(sos)
    y = _sosfilt(sos, ext, zi * ext[0])
    y = _sosfilt(sos, y[::-1].copy(), zi * y[-1])[::-1]
    return y[pad:-pad].copy()
