// The lattice-visibility measure (lattice_measure.hpp). Plain CPU code.
#include "lattice_measure.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>

#include "splatfx/dynamics.hpp"

namespace lattice {
namespace {

using Complex = std::complex<double>;
constexpr double kPi = 3.14159265358979323846;

int nextPow2(int n) {
    int p = 1;
    while (p < n) p <<= 1;
    return p;
}

// In-place iterative radix-2 FFT of n = 2^k values spaced `stride` apart.
void fft1d(Complex* data, int n, int stride, bool inverse) {
    for (int i = 1, j = 0; i < n; ++i) {
        int bit = n >> 1;
        for (; j & bit; bit >>= 1) j ^= bit;
        j ^= bit;
        if (i < j) std::swap(data[i * stride], data[j * stride]);
    }
    for (int len = 2; len <= n; len <<= 1) {
        const double a = (inverse ? 2.0 : -2.0) * kPi / len;
        const Complex wl(std::cos(a), std::sin(a));
        for (int i = 0; i < n; i += len) {
            Complex w(1.0, 0.0);
            for (int k = 0; k < len / 2; ++k) {
                Complex& x = data[(i + k) * stride];
                Complex& y = data[(i + k + len / 2) * stride];
                const Complex t = y * w;
                y = x - t;
                x += t;
                w *= wl;
            }
        }
    }
}

void fft2d(std::vector<Complex>& d, glm::ivec2 n, bool inverse) {
    for (int y = 0; y < n.y; ++y) fft1d(d.data() + std::size_t(y) * n.x, n.x, 1, inverse);
    for (int x = 0; x < n.x; ++x) fft1d(d.data() + x, n.y, n.x, inverse);
}

// Frequency (cycles per pixel) of bin (i, j) of an n.x by n.y transform.
glm::dvec2 binFrequency(int i, int j, glm::ivec2 n) {
    return {double(i <= n.x / 2 ? i : i - n.x) / n.x, double(j <= n.y / 2 ? j : j - n.y) / n.y};
}

double unit(std::uint32_t h) { return double(h >> 8) / 16777216.0; }

} // namespace

std::vector<Basis::Probe> Basis::probes() const {
    // J: 2 x 3, columns the axes; its rows as 3-vectors over the cell axes.
    const glm::dvec3 r0(axis[0].x, axis[1].x, axis[2].x), r1(axis[0].y, axis[1].y, axis[2].y);
    const double a = glm::dot(r0, r0), b = glm::dot(r0, r1), c = glm::dot(r1, r1), det = a * c - b * b;
    std::vector<Probe> out;
    if (!(std::abs(det) > 1e-12)) return out;
    const glm::dvec3 view = glm::length(glm::dvec3(viewCells)) > 0.0 ? glm::normalize(glm::dvec3(viewCells)) : glm::dvec3(0, 0, 1);
    std::vector<glm::ivec3> qs;
    const glm::ivec3 e[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int i = 0; i < 3; ++i) qs.push_back(e[i]);
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j) qs.push_back(e[i] + e[j]), qs.push_back(e[i] - e[j]);
    for (int i = 0; i < 3; ++i) qs.push_back(2 * e[i]);
    for (const glm::ivec3& q : qs) {
        const glm::dvec3 qd(q);
        if (std::abs(glm::dot(qd, view)) > 0.3) continue; // integrated out by the projection
        const glm::dvec2 jq(glm::dot(r0, qd), glm::dot(r1, qd));
        const glm::dvec2 f((c * jq.x - b * jq.y) / det, (a * jq.y - b * jq.x) / det);
        const double len = glm::length(f);
        if (!(len > 0.0) || len > 1.0 / 3.0) continue; // beyond a 3-pixel period the stamps are not resolved
        char label[32];
        std::snprintf(label, sizeof label, "(%d,%d,%d)", q.x, q.y, q.z);
        out.push_back({q, glm::vec2(f), label});
    }
    return out;
}

float Basis::shortestPeriodPx() const {
    float best = 0.0f;
    for (const Probe& p : probes()) {
        const float period = 1.0f / glm::length(p.frequency);
        best = best == 0.0f ? period : std::min(best, period);
    }
    return best;
}

// Three passes of a box of width 2r + 1 along x then y: a Gaussian of variance
// 3 ((2r + 1)^2 - 1) / 12 to within a few percent, at a cost independent of r.
std::vector<float> boxBlur3(const std::vector<float>& image, int w, int h, float sigma) {
    const int r = std::max(1, int(std::lround(0.5 * (std::sqrt(4.0 * double(sigma) * sigma + 1.0) - 1.0))));
    std::vector<float> a = image, b(image.size());
    auto pass = [&](const std::vector<float>& in, std::vector<float>& out, bool alongX) {
        const int n = alongX ? w : h, lines = alongX ? h : w;
        for (int l = 0; l < lines; ++l) {
            auto at = [&](int i) { return alongX ? in[std::size_t(l) * w + std::clamp(i, 0, n - 1)] : in[std::size_t(std::clamp(i, 0, n - 1)) * w + l]; };
            double sum = 0.0;
            for (int i = -r; i <= r; ++i) sum += at(i);
            for (int i = 0; i < n; ++i) {
                (alongX ? out[std::size_t(l) * w + i] : out[std::size_t(i) * w + l]) = float(sum / (2 * r + 1));
                sum += at(i + r + 1) - at(i - r);
            }
        }
    };
    for (int k = 0; k < 3; ++k) pass(a, b, true), pass(b, a, false);
    return a;
}

std::vector<float> blur(const std::vector<float>& image, int w, int h, float sigma) {
    if (!(sigma > 0.0f)) return image;
    if (sigma > 8.0f) return boxBlur3(image, w, h, sigma); // the masks' wide blurs: exactness does not matter there
    const int r = std::max(1, int(std::ceil(3.0f * sigma)));
    std::vector<float> k(std::size_t(2 * r + 1));
    float sum = 0.0f;
    for (int i = -r; i <= r; ++i) sum += k[std::size_t(i + r)] = std::exp(-0.5f * float(i * i) / (sigma * sigma));
    for (float& v : k) v /= sum;
    std::vector<float> tmp(image.size()), out(image.size());
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0.0f;
            for (int i = -r; i <= r; ++i) s += k[std::size_t(i + r)] * image[std::size_t(y) * w + std::clamp(x + i, 0, w - 1)];
            tmp[std::size_t(y) * w + x] = s;
        }
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float s = 0.0f;
            for (int i = -r; i <= r; ++i) s += k[std::size_t(i + r)] * tmp[std::size_t(std::clamp(y + i, 0, h - 1)) * w + x];
            out[std::size_t(y) * w + x] = s;
        }
    return out;
}

std::vector<float> flameMask(const std::vector<float>& lum, int w, int h, float sigma, float lo, float hi) {
    return maskOfBlurred(blur(lum, w, h, sigma), lo, hi);
}

std::vector<float> maskOfBlurred(const std::vector<float>& b, float lo, float hi) {
    const float top = b.empty() ? 0.0f : *std::max_element(b.begin(), b.end());
    std::vector<float> m(b.size(), 0.0f);
    if (!(top > 0.0f)) return m;
    for (std::size_t i = 0; i < b.size(); ++i) {
        const float t = std::clamp((b[i] / top - lo) / (hi - lo), 0.0f, 1.0f);
        m[i] = t * t * (3.0f - 2.0f * t);
    }
    return m;
}

Accumulator::Accumulator(glm::ivec2 size) : mSize(size), mFft(nextPow2(size.x), nextPow2(size.y)), mPower(std::size_t(mFft.x) * mFft.y, 0.0) {}

void Accumulator::add(const std::vector<float>& lum, const std::vector<float>& mask, const Basis& basis) {
    const int w = mSize.x, h = mSize.y;
    // High-pass: minus a blur of half the shortest lattice period, which keeps
    // every probe (transfer 1 - exp(-pi^2 / 2) >= 0.99 there) and removes the
    // flame's large-scale shape.
    const float period = basis.shortestPeriodPx();
    const std::vector<float> low = blur(lum, w, h, 0.5f * (period > 0.0f ? period : 4.0f));
    std::vector<Complex> d(std::size_t(mFft.x) * mFft.y, Complex(0.0, 0.0));
    double maskSum = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * w + x;
            d[std::size_t(y) * mFft.x + x] = double(mask[i]) * double(lum[i] - low[i]);
            maskSum += mask[i];
        }
    fft2d(d, mFft, false);
    // Normalised by the mask's area, so frames with more flame do not dominate.
    const double norm = 1.0 / std::max(maskSum, 1.0);
    for (std::size_t i = 0; i < d.size(); ++i) mPower[i] += std::norm(d[i]) * norm;
    ++mFrames;
}

Score Accumulator::score(const Basis& basis) const {
    Score s;
    s.frames = mFrames;
    const std::vector<Basis::Probe> probes = basis.probes();
    if (mFrames == 0 || probes.empty()) return s;
    // The disc a peak is looked for in: 8 % of its frequency (the projected
    // spacing changes by about that across an effect seen in perspective),
    // at least 1.5 bins.
    const double binSize = std::max(1.0 / mFft.x, 1.0 / mFft.y);
    auto discRadius = [&](glm::dvec2 f) { return std::max(0.08 * glm::length(f), 1.5 * binSize); };
    std::vector<double> ring;
    for (const Basis::Probe& p : probes) {
        const glm::dvec2 f(p.frequency);
        const double fl = glm::length(f), r = discRadius(f);
        double peak = 0.0;
        int peakBins = 0;
        ring.clear();
        for (int j = 0; j < mFft.y; ++j)
            for (int i = 0; i < mFft.x; ++i) {
                const glm::dvec2 k = binFrequency(i, j, mFft);
                const double kl = glm::length(k);
                if (std::abs(kl - fl) > 0.12 * fl + binSize) continue;
                const double pw = mPower[std::size_t(j) * mFft.x + i];
                if (glm::length(k - f) <= r || glm::length(k + f) <= r) {
                    peak += pw;
                    ++peakBins;
                    continue;
                }
                bool nearProbe = false; // the ring leaves out every lattice frequency
                for (const Basis::Probe& o : probes) {
                    const glm::dvec2 g(o.frequency);
                    const double ro = 2.0 * discRadius(g);
                    nearProbe = nearProbe || glm::length(k - g) <= ro || glm::length(k + g) <= ro;
                }
                if (!nearProbe) ring.push_back(pw);
            }
        if (ring.empty() || peakBins == 0) continue;
        // The same direction at other periods: discs (radius scaled with the
        // frequency) at 0.75 f and 4/3 f, leaving out every lattice frequency.
        double alongLog = 0.0;
        int alongDiscs = 0;
        for (const double scale : {0.75, 4.0 / 3.0}) {
            const glm::dvec2 g = scale * f;
            const double rg = scale * r;
            double sum = 0.0;
            int bins = 0;
            for (int j = 0; j < mFft.y; ++j)
                for (int i = 0; i < mFft.x; ++i) {
                    const glm::dvec2 k = binFrequency(i, j, mFft);
                    if (glm::length(k - g) > rg && glm::length(k + g) > rg) continue;
                    bool nearProbe = false;
                    for (const Basis::Probe& o : probes) {
                        const glm::dvec2 h(o.frequency);
                        const double ro = 2.0 * discRadius(h);
                        nearProbe = nearProbe || glm::length(k - h) <= ro || glm::length(k + h) <= ro;
                    }
                    if (!nearProbe) sum += mPower[std::size_t(j) * mFft.x + i], ++bins;
                }
            if (bins > 0 && sum > 0.0) alongLog += std::log(sum / bins), ++alongDiscs;
        }
        double ringMean = 0.0;
        for (double v : ring) ringMean += v;
        ringMean /= double(ring.size());
        peak /= double(peakBins);
        ProbeScore ps{p, peak, ringMean, ringMean > 0.0 ? peak / ringMean : 0.0};
        if (alongDiscs > 0) ps.along = std::exp(alongLog / alongDiscs), ps.peak = peak / ps.along;
        s.probes.push_back(ps);
        s.ratio = std::max(s.ratio, ps.ratio);
        s.peak = std::max(s.peak, ps.peak);
        s.meanRatio += ps.ratio;
    }
    if (!s.probes.empty()) s.meanRatio /= double(s.probes.size());
    return s;
}

Turbulence::Turbulence(glm::ivec2 size, float beta, std::uint32_t seed) : mSize(size), mFft(nextPow2(size.x), nextPow2(size.y)) {
    const std::size_t n = std::size_t(mFft.x) * mFft.y;
    mAmplitude.resize(n);
    mPhase.resize(n);
    mSpeed.resize(n);
    for (int j = 0; j < mFft.y; ++j)
        for (int i = 0; i < mFft.x; ++i) {
            const std::size_t b = std::size_t(j) * mFft.x + i;
            const double k = glm::length(binFrequency(i, j, mFft));
            // Power ~ k^-beta; nothing below a 256-pixel period (the flame's shape, not its texture).
            mAmplitude[b] = k > 1.0 / 256.0 ? float(std::pow(k, -0.5 * beta)) : 0.0f;
            const std::uint32_t h = splatfx::hash32(seed * 0x9e3779b9u ^ splatfx::hash32(std::uint32_t(b) + 1u));
            mPhase[b] = float(2.0 * kPi * unit(h));
            mSpeed[b] = float(6.0 * (unit(splatfx::hash32(h)) - 0.5)); // rad / s: the field churns, it does not translate
        }
}

std::vector<float> Turbulence::frame(double t) const {
    std::vector<Complex> d(mAmplitude.size());
    for (std::size_t b = 0; b < d.size(); ++b) d[b] = std::polar(double(mAmplitude[b]), double(mPhase[b]) + double(mSpeed[b]) * t);
    fft2d(d, mFft, true);
    std::vector<float> out(std::size_t(mSize.x) * mSize.y);
    double sum = 0.0, sum2 = 0.0;
    for (int y = 0; y < mSize.y; ++y)
        for (int x = 0; x < mSize.x; ++x) {
            const double v = d[std::size_t(y) * mFft.x + x].real();
            out[std::size_t(y) * mSize.x + x] = float(v);
            sum += v, sum2 += v * v;
        }
    const double n = double(out.size()), mean = sum / n, sd = std::sqrt(std::max(sum2 / n - mean * mean, 1e-30));
    for (float& v : out) v = float((v - mean) / sd);
    return out;
}

} // namespace lattice
