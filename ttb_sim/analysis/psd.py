# Copyright 2026 The ttb_sim Authors
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Power spectral densities of response records and the features read from them (V19).

All densities are one-sided, in (signal unit)^2/Hz, with Hann windows, so that
``sum(p) * df`` equals the Hann-weighted mean square of the detrended record
(Parseval), i.e. its variance for a stationary record.

- :func:`welch_psd` -- Welch average of Hann-windowed segments with 50 %
  overlap (MATLAB's ``pwelch``, used by the paper in section 4.1).  The bin
  spacing is ``1 / segment_seconds``; by default the record is cut into seven
  segments of a quarter of its length, so a 10 s record has 0.4 Hz bins.
- :func:`padded_periodogram` -- one Hann-windowed periodogram of the whole
  record, zero-padded.  For short records whose low-frequency peaks a Welch
  average resolves too coarsely (a 10 s record has 0.4 Hz Welch bins around the
  0.84 Hz car-body mode).  Zero padding only interpolates: the resolution stays
  that of the Hann window over the record, equivalent noise bandwidth 1.5 / T
  (0.15 Hz for T = 10 s), and each bin has only two degrees of freedom.
  Note that no estimator places a broad peak from one short random record:
  for a mode with 30 % damping seen in a 10 s record the peak scatters by
  about 25 %, because |H|^2 drops only 2 % at +-5 % from its maximum.
- :func:`peak_frequency` -- largest value inside a band, refined to a fraction
  of a bin by a parabola through log p at the three bins around the maximum
  (or fitted to ``fit_bins`` bins, for broad peaks estimated with scatter).
- :func:`level_change_frequency` -- where log p has its largest step between
  two power laws fitted below and above each candidate break (the V/lambda
  change of the irregularity spectrum, 83.3 Hz at 300 km/h for lambda = 1 m).
"""

from __future__ import annotations

import logging

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import fft as sfft
from scipy import signal as ssig

from ttb_sim.errors import ScenarioError

__all__ = [
    'MIN_SEGMENT_SAMPLES',
    'MIN_WINDOW_BINS',
    'level_change_frequency',
    'padded_periodogram',
    'peak_frequency',
    'welch_psd',
]

_LOG = logging.getLogger(__name__)

#: Fewest samples of a record or of one Welch segment.
MIN_SEGMENT_SAMPLES: int = 8
#: Fewest bins on each side of a candidate break in :func:`level_change_frequency`.
MIN_WINDOW_BINS: int = 3
_DETRENDS = ('constant', 'linear', False)
_DIRECTIONS = ('down', 'up', 'either')


def _record(signal: ArrayLike) -> NDArray[np.float64]:
    """Return the signal as a finite 1-D float array of at least MIN_SEGMENT_SAMPLES samples."""
    x = np.asarray(signal, dtype=float)
    if x.ndim != 1:
        raise ScenarioError(f'signal must be a 1-D array, got shape {x.shape}')
    if x.size < MIN_SEGMENT_SAMPLES:
        raise ScenarioError(
            f'signal must have at least {MIN_SEGMENT_SAMPLES} samples, got {x.size}')
    bad = np.flatnonzero(~np.isfinite(x))
    if bad.size:
        raise ScenarioError(
            f'signal must be finite, got {x[bad[0]]} at sample {bad[0]} '
            f'({bad.size} non-finite samples)')
    return x


def _positive(name: str, value: float) -> float:
    """Return value as a float, or raise ScenarioError unless it is finite and > 0."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ScenarioError(f'{name} must be a finite number > 0, got {value!r}') from None
    if not (np.isfinite(number) and number > 0.0):
        raise ScenarioError(f'{name} must be a finite number > 0, got {value!r}')
    return number


def _detrend(detrend: str | bool) -> str | bool:
    """Return the detrend option, or raise ScenarioError for an unknown one."""
    if isinstance(detrend, bool):
        if detrend:
            raise ScenarioError(
                f"detrend must be one of 'constant', 'linear' or False, got {detrend!r}")
        return False
    if detrend not in _DETRENDS:
        raise ScenarioError(
            f"detrend must be one of 'constant', 'linear' or False, got {detrend!r}")
    return detrend


def welch_psd(signal: ArrayLike, sample_rate: float, segment_seconds: float | None = None,
              detrend: str | bool = 'constant') -> tuple[NDArray[np.float64],
                                                         NDArray[np.float64]]:
    """
    Return the one-sided Welch PSD of a record (Hann windows, 50 % overlap).

    Parameters
    ----------
    signal : array_like
        Uniformly sampled 1-D record, finite, at least ``MIN_SEGMENT_SAMPLES`` long.
    sample_rate : float
        Sampling rate (Hz), > 0.
    segment_seconds : float, optional
        Length of one Welch segment (s); rounded to whole samples, which must
        lie between ``MIN_SEGMENT_SAMPLES`` and the record length.  The bin
        spacing is ``sample_rate / round(segment_seconds * sample_rate)``.  By
        default a quarter of the record (seven averaged segments); a record
        shorter than ``4 * MIN_SEGMENT_SAMPLES`` is taken as one segment.  The
        paper's 20 m window at 300 km/h is ``segment_seconds = 0.24``.
    detrend : {'constant', 'linear', False}
        Trend removed from each segment before windowing.

    Returns
    -------
    f : ndarray
        Frequencies (Hz), ``0 .. sample_rate / 2``.
    p : ndarray
        PSD in (signal unit)^2/Hz; ``sum(p) * (f[1] - f[0])`` is the mean square
        (Hann-weighted within each segment).

    Raises
    ------
    ScenarioError
        For a record that is not 1-D, too short or not finite, a rate that is
        not > 0, a segment outside the allowed length or an unknown detrend.

    """
    x = _record(signal)
    fs = _positive('sample_rate', sample_rate)
    trend = _detrend(detrend)
    if segment_seconds is None:
        nperseg = x.size // 4 if x.size >= 4 * MIN_SEGMENT_SAMPLES else x.size
    else:
        seconds = _positive('segment_seconds', segment_seconds)
        nperseg = int(round(seconds * fs))
        if not MIN_SEGMENT_SAMPLES <= nperseg <= x.size:
            raise ScenarioError(
                f'segment_seconds must give between {MIN_SEGMENT_SAMPLES} and {x.size} samples '
                f'(the record, {x.size / fs:g} s at {fs:g} Hz), got {segment_seconds!r} s '
                f'= {nperseg} samples')
    f, p = ssig.welch(x, fs=fs, window='hann', nperseg=nperseg, noverlap=nperseg // 2,
                      detrend=trend, return_onesided=True, scaling='density', average='mean')
    _LOG.debug('Welch PSD: %d samples, %d per segment, bin %.4g Hz',
               x.size, nperseg, fs / nperseg)
    return f, p


def padded_periodogram(signal: ArrayLike, sample_rate: float, pad_factor: int = 8,
                       detrend: str | bool = 'constant') -> tuple[NDArray[np.float64],
                                                                  NDArray[np.float64]]:
    """
    Return the one-sided Hann periodogram of the whole record, zero-padded.

    The bins are ``sample_rate / nfft`` apart with ``nfft`` the fast FFT length
    of at least ``pad_factor`` times the record, but padding only interpolates
    the spectrum of the Hann-windowed record: two peaks closer than about
    ``2 / T`` are not separated, the equivalent noise bandwidth is ``1.5 / T``
    and, for a random record, each value has two degrees of freedom (a
    standard deviation equal to its mean).  Use it to place a peak of a short
    record (T = 10 s: bins 0.0125 Hz, bandwidth 0.15 Hz), not to read levels.

    Parameters
    ----------
    signal : array_like
        Uniformly sampled 1-D record, finite, at least ``MIN_SEGMENT_SAMPLES`` long.
    sample_rate : float
        Sampling rate (Hz), > 0.
    pad_factor : int
        Ratio of the FFT length to the record length, >= 1.
    detrend : {'constant', 'linear', False}
        Trend removed from the record before windowing.

    Returns
    -------
    f, p : ndarray
        Frequencies (Hz) and PSD in (signal unit)^2/Hz; ``sum(p) * (f[1] - f[0])``
        is the Hann-weighted mean square of the detrended record.

    Raises
    ------
    ScenarioError
        As :func:`welch_psd`, and for a pad factor that is not an integer >= 1.

    """
    x = _record(signal)
    fs = _positive('sample_rate', sample_rate)
    trend = _detrend(detrend)
    if isinstance(pad_factor, bool) or not isinstance(pad_factor, (int, np.integer)) \
            or pad_factor < 1:
        raise ScenarioError(f'pad_factor must be an integer >= 1, got {pad_factor!r}')
    nfft = sfft.next_fast_len(int(pad_factor) * x.size, real=True)
    f, p = ssig.periodogram(x, fs=fs, window='hann', nfft=nfft, detrend=trend,
                            return_onesided=True, scaling='density')
    _LOG.debug('Padded periodogram: %d samples, nfft %d, bin %.4g Hz, bandwidth %.4g Hz',
               x.size, nfft, fs / nfft, 1.5 * fs / x.size)
    return f, p


def _spectrum(f: ArrayLike, p: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return f and p as matching finite 1-D arrays, f increasing and p >= 0."""
    freq = np.asarray(f, dtype=float)
    psd = np.asarray(p, dtype=float)
    if freq.ndim != 1 or psd.shape != freq.shape:
        raise ScenarioError(
            f'f and p must be 1-D arrays of the same length, got shapes {freq.shape} '
            f'and {psd.shape}')
    if freq.size < 3:
        raise ScenarioError(f'f and p must have at least 3 bins, got {freq.size}')
    if not (np.all(np.isfinite(freq)) and np.all(np.isfinite(psd))):
        raise ScenarioError('f and p must be finite, got NaN or infinite values')
    if np.any(np.diff(freq) <= 0.0):
        raise ScenarioError('f must be strictly increasing')
    if np.any(psd < 0.0):
        raise ScenarioError(f'p must be >= 0, got minimum {psd.min()!r}')
    return freq, psd


def _band(freq: NDArray[np.float64], band: tuple[float, float] | None) -> NDArray[np.intp]:
    """Return the indices of the bins with lo <= f <= hi (all bins for None)."""
    if band is None:
        return np.arange(freq.size)
    try:
        lo, hi = (float(b) for b in band)
    except (TypeError, ValueError):
        raise ScenarioError(f'band must be a pair (lo, hi) of numbers in Hz, got {band!r}') \
            from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise ScenarioError(f'band must satisfy lo < hi, both finite, got {band!r}')
    index = np.flatnonzero((freq >= lo) & (freq <= hi))
    if index.size == 0:
        raise ScenarioError(
            f'band {band!r} Hz holds no bin of f ({freq[0]:g} .. {freq[-1]:g} Hz)')
    return index


def peak_frequency(f: ArrayLike, p: ArrayLike, band: tuple[float, float] | None = None,
                   fit_bins: int = 3) -> float:
    """
    Return the frequency of the largest PSD value in a band, refined below a bin.

    A parabola in ``log p`` against f is fitted to the maximum bin and its
    neighbours -- through the three bins around it by default, by least
    squares over ``fit_bins`` bins centred on it otherwise -- and its vertex
    is returned.  Neighbours come from the whole spectrum, so a maximum on a
    band edge is refined too.  For a sinusoid seen through a Hann window the
    three-bin error is below 0.05 bin (the main lobe is close to a Gaussian,
    whose log is a parabola).  A wider fit suits a broad peak estimated with
    scatter (a damped mode in a short random record): spread it over the
    half-power band.  The bin frequency is returned unrefined when the
    maximum is at either end of ``f``, when it is not a local maximum (the
    peak lies outside the band; a warning is logged), when a bin of the fit
    is zero, or when the fitted parabola opens upwards.

    Parameters
    ----------
    f : array_like
        Increasing frequencies (Hz), 1-D; non-uniform spacing is allowed.
    p : array_like
        PSD values >= 0 at ``f``.
    band : (float, float), optional
        Inclusive search band ``(lo, hi)`` in Hz; the whole spectrum by default.
    fit_bins : int
        Odd number of bins, >= 3, of the parabola (fewer at the ends of ``f``).

    Returns
    -------
    float
        Peak frequency (Hz), inside the fitted bins.

    Raises
    ------
    ScenarioError
        For mismatched, non-finite or negative input, a band holding no bin,
        or ``fit_bins`` not an odd integer >= 3.

    """
    freq, psd = _spectrum(f, p)
    if isinstance(fit_bins, bool) or not isinstance(fit_bins, (int, np.integer)) \
            or fit_bins < 3 or fit_bins % 2 == 0:
        raise ScenarioError(f'fit_bins must be an odd integer >= 3, got {fit_bins!r}')
    index = _band(freq, band)
    i = int(index[np.argmax(psd[index])])
    if i == 0 or i == freq.size - 1:
        return float(freq[i])
    if psd[i] < psd[i - 1] or psd[i] < psd[i + 1]:
        _LOG.warning('PSD maximum in band %r is at its edge %.6g Hz and rises outside it',
                     band, freq[i])
        return float(freq[i])
    half = int(fit_bins) // 2
    lo, hi = max(0, i - half), min(freq.size, i + half + 1)
    x, values = freq[lo:hi] - freq[i], psd[lo:hi]
    if np.any(values <= 0.0):
        return float(freq[i])
    curvature, slope, _ = np.polyfit(x, np.log(values), 2)
    if curvature >= 0.0:
        return float(freq[i])
    vertex = freq[i] - 0.5 * slope / curvature
    return float(np.clip(vertex, freq[lo], freq[hi - 1]))


def _line_at(x: NDArray[np.float64], y: NDArray[np.float64], width: int,
             at: NDArray[np.float64]) -> NDArray[np.float64]:
    """
    Return least-squares lines through every ``width`` consecutive points, evaluated.

    Window ``j`` covers ``x[j:j + width]``; its line is evaluated at ``at[j]``.
    Sliding sums are differences of cumulative sums, so the cost is O(len(x)).
    """
    def sliding(values: NDArray[np.float64]) -> NDArray[np.float64]:
        total = np.concatenate(([0.0], np.cumsum(values)))
        return total[width:] - total[:-width]

    sx, sy = sliding(x), sliding(y)
    sxx, sxy = sliding(x * x), sliding(x * y)
    spread = width * sxx - sx * sx
    slope = np.divide(width * sxy - sx * sy, spread, out=np.zeros_like(spread),
                      where=spread > 0.0)
    return (sy - slope * sx) / width + slope * at


def _positive_band(freq: NDArray[np.float64], psd: NDArray[np.float64],
                   band: tuple[float, float] | None
                   ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return f and p inside the band (without a zero-frequency bin), both > 0 there."""
    index = _band(freq, band)
    if band is None:
        index = index[freq[index] > 0.0]
    sel_f, sel_p = freq[index], psd[index]
    if sel_f[0] <= 0.0 or np.any(sel_p <= 0.0):
        raise ScenarioError(
            f'f and p must be > 0 inside band {band!r}, got f from {sel_f[0]!r} Hz and '
            f'minimum p {sel_p.min()!r}')
    return sel_f, sel_p


def _window_width(window_bins: int | None, count: int, band: tuple[float, float] | None) -> int:
    """Return the bins fitted on each side of a break (checked against the band's bins)."""
    if window_bins is None:
        width = max(MIN_WINDOW_BINS, count // 8)
    elif isinstance(window_bins, bool) or not isinstance(window_bins, (int, np.integer)) \
            or window_bins < MIN_WINDOW_BINS:
        raise ScenarioError(
            f'window_bins must be an integer >= {MIN_WINDOW_BINS}, got {window_bins!r}')
    else:
        width = int(window_bins)
    if count < 2 * width:
        raise ScenarioError(
            f'band {band!r} must hold at least 2 * window_bins = {2 * width} bins, '
            f'got {count}')
    return width


def _level_steps(sel_f: NDArray[np.float64], sel_p: NDArray[np.float64], width: int
                 ) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """Return the candidate breaks and the level step (decades) of the two fits at each."""
    count = sel_f.size
    log_f = np.log10(sel_f)
    centre = log_f.mean()
    x = log_f - centre
    y = np.log10(sel_p)
    # Break k lies between bins k - 1 and k, k = width .. count - width.
    breaks = np.arange(width, count - width + 1)
    x_break = np.log10(0.5 * (sel_f[breaks - 1] + sel_f[breaks])) - centre
    below = _line_at(x, y, width, np.pad(x_break, (0, width)))[breaks - width]
    above = _line_at(x, y, width, np.pad(x_break, (width, 0)))[breaks]
    return breaks, above - below


def level_change_frequency(f: ArrayLike, p: ArrayLike,
                           band: tuple[float, float] | None = None,
                           window_bins: int | None = None,
                           direction: str = 'either') -> float:
    """
    Return the frequency where the PSD level steps most sharply inside a band.

    Method (a two-segment power-law fit): every boundary between two bins
    inside the band is a candidate break ``fb`` (the midpoint of the two bins).
    A straight line in ``log10 p`` against ``log10 f`` is fitted by least
    squares to the ``window_bins`` bins just below the break and another to
    the ``window_bins`` bins just above, and both are evaluated at ``fb``;
    their difference is the level step in decades.  A power-law background
    (any slope) gives no step, so only the discontinuity is found, and the
    break with the largest step in the requested direction is returned.

    Resolution: the answer is a bin boundary, and a sharp step is placed
    within one bin ``df`` of the truth in the absence of noise.  The Hann
    window mixes p (not log p) over about two bins on each side of the step,
    so the log-domain midpoint of the smeared step lies up to about half a bin
    towards the lower level (measured: a 10x drop is found 0.1 bin below to
    0.8 bin above the true frequency, a 2.7x rise 0.7 bin below to 0.2 bin
    above).  Estimation noise adds a few bins when the step is small against
    the scatter of log p (Welch with K segments: about 0.43 / sqrt(K) decades
    per bin) averaged over ``window_bins``; a 10x step with K = 7 stays within
    one bin, a 2.7x step with K = 7 and the default window misses by more
    than 5 % in about 1.5 % of records (with K = 65, the paper's 0.24 s
    window in 8 s, it stays within 0.51 bin).

    Parameters
    ----------
    f : array_like
        Increasing frequencies (Hz), 1-D, > 0 inside the band.
    p : array_like
        PSD values at ``f``, > 0 inside the band.
    band : (float, float), optional
        Inclusive band ``(lo, hi)`` in Hz that holds both fit windows of every
        candidate; the whole spectrum (without a zero-frequency bin) by default.
    window_bins : int, optional
        Bins fitted on each side of a break, >= ``MIN_WINDOW_BINS``; the band
        must hold at least ``2 * window_bins`` bins.  By default an eighth of
        the bins in the band, at least ``MIN_WINDOW_BINS``.
    direction : {'either', 'down', 'up'}
        Look for the largest step in either direction, the largest drop of the
        level with increasing frequency, or the largest rise.  At 300 km/h the
        Chinese-to-Sato change at lambda = 1 m (83.3 Hz) is a rise of the
        irregularity PSD by a factor of about 2.7.

    Returns
    -------
    float
        Break frequency (Hz).

    Raises
    ------
    ScenarioError
        For invalid spectra or band, p or f not > 0 in the band, an unknown
        direction or a window that does not fit twice into the band.

    """
    freq, psd = _spectrum(f, p)
    if direction not in _DIRECTIONS:
        raise ScenarioError(f"direction must be one of 'either', 'down', 'up', got {direction!r}")
    sel_f, sel_p = _positive_band(freq, psd, band)
    width = _window_width(window_bins, sel_f.size, band)
    breaks, step = _level_steps(sel_f, sel_p, width)
    if direction == 'down':
        j = int(np.argmin(step))
    elif direction == 'up':
        j = int(np.argmax(step))
    else:
        j = int(np.argmax(np.abs(step)))
    k = breaks[j]
    found = 0.5 * (sel_f[k - 1] + sel_f[k])
    if (direction == 'down' and step[j] >= 0.0) or (direction == 'up' and step[j] <= 0.0):
        _LOG.warning('No level %s inside band %r; largest step %.3g decades at %.6g Hz',
                     direction, band, step[j], found)
    _LOG.debug('Level change %.3g decades at %.6g Hz (window %d bins)', step[j], found, width)
    return float(found)


def resolving_segment_seconds(lowest_hz: float, record_seconds: float,
                              bins_below: float = 6.0) -> float:
    """
    Return the Welch segment length (s) that resolves ``lowest_hz`` with ``bins_below`` bins.

    The bin spacing ``1 / T`` must be ``lowest_hz / bins_below`` or finer:
    0.84 Hz (the car-body mode) needs 7.1 s segments, where [P]'s 20 m window
    at 300 km/h (0.24 s, 4.2 Hz bins) cannot see it (PHYSICS.md section 8).  A
    record shorter than that is taken whole (one Hann segment) and its coarser
    resolution is logged.
    """
    lowest = _positive('lowest_hz', lowest_hz)
    record = _positive('record_seconds', record_seconds)
    wanted = _positive('bins_below', bins_below) / lowest
    if wanted > record:
        _LOG.info('record of %.3g s is shorter than the %.3g s segment that resolves %.3g Hz '
                  'with %g bins: one segment, bins of %.3g Hz', record, wanted, lowest,
                  bins_below, 1.0 / record)
        return record
    return wanted
