// signal_tools.hpp -- independent signal analysis for the core tests: a plain
// radix-2 FFT, interpolated spectral peaks, and linear-prediction (Prony) fits of
// damped sinusoids. None of it uses the code under test.
#pragma once
#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

extern "C" {
#include "contact.h"
#include "membrane.h"
}

namespace tools
{

using cd = std::complex<double>;

inline void fft(std::vector<cd> &a)
{
    const size_t n = a.size();
    for (size_t i = 1, j = 0; i < n; i++) {
        size_t bit = n >> 1;
        for (; j & bit; bit >>= 1)
            j ^= bit;
        j ^= bit;
        if (i < j)
            std::swap(a[i], a[j]);
    }
    for (size_t len = 2; len <= n; len <<= 1) {
        const double ang = -2.0 * M_PI / (double)len;
        for (size_t i = 0; i < n; i += len) {
            for (size_t k = 0; k < len / 2; k++) {
                cd w = std::polar(1.0, ang * (double)k);
                cd u = a[i + k], v = a[i + k + len / 2] * w;
                a[i + k] = u + v;
                a[i + k + len / 2] = u - v;
            }
        }
    }
}

// Magnitude spectrum of a windowed signal zero-padded to `padded` points: Hann, or
// 4-term Blackman-Harris (sidelobes below -92 dB) for "is anything there" checks.
inline std::vector<double> spectrum(const std::vector<float> &x, size_t padded,
                                    bool blackman_harris = false)
{
    std::vector<cd> a(padded, 0.0);
    const size_t n = x.size();
    for (size_t i = 0; i < n; i++) {
        double ph = 2.0 * M_PI * (double)i / (double)n;
        double w = blackman_harris ? 0.35875 - 0.48829 * std::cos(ph) +
                                         0.14128 * std::cos(2.0 * ph) - 0.01168 * std::cos(3.0 * ph)
                                   : 0.5 - 0.5 * std::cos(ph);
        a[i] = x[i] * w;
    }
    fft(a);
    std::vector<double> mag(padded / 2);
    for (size_t i = 0; i < padded / 2; i++)
        mag[i] = std::abs(a[i]);
    return mag;
}

// Frequency (Hz) of the largest peak within +-search_hz of guess_hz, refined by a
// parabola through the log magnitudes of the three top bins (Gaussian
// interpolation: nearly exact for a zero-padded Hann main lobe).
inline double peak_frequency(const std::vector<double> &mag, double bin_hz, double guess_hz,
                             double search_hz, double *peak_mag = nullptr)
{
    long lo = (long)((guess_hz - search_hz) / bin_hz), hi = (long)((guess_hz + search_hz) / bin_hz);
    if (lo < 1)
        lo = 1;
    long best = lo;
    for (long i = lo; i <= hi; i++)
        if (mag[i] > mag[best])
            best = i;
    double a = std::log(mag[best - 1]), b = std::log(mag[best]), c = std::log(mag[best + 1]);
    double delta = 0.5 * (a - c) / (a - 2.0 * b + c);
    if (peak_mag)
        *peak_mag = mag[best];
    return ((double)best + delta) * bin_hz;
}

// Largest magnitude within +-half_width_hz of f (for "is anything there" checks).
inline double band_max(const std::vector<double> &mag, double bin_hz, double f,
                       double half_width_hz)
{
    long lo = (long)((f - half_width_hz) / bin_hz), hi = (long)((f + half_width_hz) / bin_hz) + 1;
    double m = 0.0;
    for (long i = lo; i <= hi; i++)
        if (i >= 0 && (size_t)i < mag.size() && mag[i] > m)
            m = mag[i];
    return m;
}

// Roots of a monic polynomial z^n + c[0] z^(n-1) + ... + c[n-1] (Durand-Kerner).
inline std::vector<cd> poly_roots(const std::vector<double> &c)
{
    const size_t n = c.size();
    std::vector<cd> z(n);
    for (size_t i = 0; i < n; i++)
        z[i] = std::pow(cd(0.4, 0.9), (double)i);
    for (int it = 0; it < 2000; it++) {
        double moved = 0.0;
        for (size_t i = 0; i < n; i++) {
            cd p = 1.0;
            for (size_t k = 0; k < n; k++)
                p = p * z[i] + c[k];
            cd d = 1.0;
            for (size_t j = 0; j < n; j++)
                if (j != i)
                    d *= (z[i] - z[j]);
            cd step = p / d;
            z[i] -= step;
            moved += std::abs(step);
        }
        if (moved < 1e-15)
            break;
    }
    return z;
}

struct damped_mode {
    double freq_hz, decay_per_s;
};

// Least-squares linear prediction of order 2*modes (Prony): a sum of `modes`
// damped sinusoids obeys x[n] = sum a_k x[n-k]; the roots of the predictor give
// each mode's frequency and decay rate. Sorted by frequency. The signal is first
// decimated by `step` (plain subsampling: the modes stay below the new Nyquist)
// so that the predictor's roots are not crowded next to z = 1.
inline std::vector<damped_mode> prony(const std::vector<float> &full, int modes, double fs,
                                      int step = 1)
{
    std::vector<float> x;
    for (size_t i = 0; i < full.size(); i += (size_t)step)
        x.push_back(full[i]);
    fs /= step;
    const int order = 2 * modes;
    std::vector<double> A((size_t)order * order, 0.0), rhs((size_t)order, 0.0);
    for (size_t n = (size_t)order; n < x.size(); n++) {
        for (int i = 0; i < order; i++) {
            double xi = x[n - 1 - i];
            rhs[i] += xi * x[n];
            for (int j = 0; j < order; j++)
                A[(size_t)i * order + j] += xi * x[n - 1 - j];
        }
    }
    // Gaussian elimination with partial pivoting.
    for (int col = 0; col < order; col++) {
        int piv = col;
        for (int r = col + 1; r < order; r++)
            if (std::fabs(A[(size_t)r * order + col]) > std::fabs(A[(size_t)piv * order + col]))
                piv = r;
        for (int k = 0; k < order; k++)
            std::swap(A[(size_t)col * order + k], A[(size_t)piv * order + k]);
        std::swap(rhs[col], rhs[piv]);
        for (int r = col + 1; r < order; r++) {
            double f = A[(size_t)r * order + col] / A[(size_t)col * order + col];
            for (int k = col; k < order; k++)
                A[(size_t)r * order + k] -= f * A[(size_t)col * order + k];
            rhs[r] -= f * rhs[col];
        }
    }
    std::vector<double> a((size_t)order);
    for (int r = order - 1; r >= 0; r--) {
        double s = rhs[r];
        for (int k = r + 1; k < order; k++)
            s -= A[(size_t)r * order + k] * a[k];
        a[r] = s / A[(size_t)r * order + r];
    }
    std::vector<double> c((size_t)order);
    for (int i = 0; i < order; i++)
        c[i] = -a[i];
    std::vector<damped_mode> out;
    for (cd z : poly_roots(c))
        if (z.imag() > 0.0)
            out.push_back({std::arg(z) * fs / (2.0 * M_PI), -std::log(std::abs(z)) * fs});
    std::sort(out.begin(), out.end(),
              [](const damped_mode &l, const damped_mode &r) { return l.freq_hz < r.freq_hz; });
    return out;
}

inline double cents(double f, double ref)
{
    return 1200.0 * std::log2(f / ref);
}

// Renders n samples of pickup `which` in blocks of `block` (no force input).
inline std::vector<float> render(membrane *m, size_t n, int which = 0, int block = 64)
{
    std::vector<float> o0((size_t)block), o1((size_t)block), out;
    out.reserve(n);
    float *outs[2] = {o0.data(), o1.data()};
    while (out.size() < n) {
        membrane_process(m, nullptr, outs, block);
        for (int i = 0; i < block && out.size() < n; i++)
            out.push_back(which == 0 ? o0[(size_t)i] : o1[(size_t)i]);
    }
    return out;
}

} // namespace tools
