// FLIP, following ../shared/reference/flip.md section by section (§ numbers below refer to it).
#include "engine/core/flip.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh {
namespace {

constexpr float PI = 3.14159265358979323846f;
// §6 constants.
constexpr float QC = 0.7f, PC = 0.4f, PT = 0.95f, GW = 0.082f, QF = 0.5f;
// D65 reference white used by both YCxCz and CIELAB.
constexpr float WHITE[3] = {0.950428545f, 1.0f, 1.088900371f};
const float INV_WHITE[3] = {1.0f / 0.950428545f, 1.0f, 1.0f / 1.088900371f};

using Plane = std::vector<float>;

// Runs fn(y0, y1) over row bands on up to 8 threads (rows are independent in every pass).
template <class F>
void parallel_rows(int height, const F& fn) {
    const int threads = int(std::min(8u, std::max(1u, std::thread::hardware_concurrency())));
    if (threads <= 1 || height < 64) {
        fn(0, height);
        return;
    }
    std::vector<std::thread> pool;
    const int band = (height + threads - 1) / threads;
    for (int y0 = 0; y0 < height; y0 += band) pool.emplace_back([&fn, y0, band, height] { fn(y0, std::min(height, y0 + band)); });
    for (auto& t : pool) t.join();
}

// 1-D correlation along x with clamp-to-edge: out(x) = Σ_{i=-r..r} k[i+r]·in(clamp(x+i)).
// The row is copied into an edge-padded buffer so the tap loop runs over x (vectorises); each
// output still sums its taps in the order -r..r.
void conv_x(const Plane& in, Plane& out, int w, int h, const std::vector<float>& k) {
    const int r = int(k.size() / 2);
    out.resize(in.size());
    parallel_rows(h, [&](int y0, int y1) {
        std::vector<float> pad(static_cast<size_t>(w + 2 * r));
        for (int y = y0; y < y1; ++y) {
            const float* row = in.data() + size_t(y) * w;
            for (int x = -r; x < w + r; ++x) pad[size_t(x + r)] = row[std::clamp(x, 0, w - 1)];
            float* o = out.data() + size_t(y) * w;
            std::fill(o, o + w, 0.0f);
            for (int i = 0; i <= 2 * r; ++i) {
                const float kk = k[i];
                const float* src = pad.data() + i;
                for (int x = 0; x < w; ++x) o[x] += kk * src[x];
            }
        }
    });
}

// 1-D correlation along y with clamp-to-edge.
void conv_y(const Plane& in, Plane& out, int w, int h, const std::vector<float>& k) {
    const int r = int(k.size() / 2);
    out.resize(in.size());
    parallel_rows(h, [&](int y0, int y1) {
        std::vector<float> acc(static_cast<size_t>(w));
        for (int y = y0; y < y1; ++y) {
            std::fill(acc.begin(), acc.end(), 0.0f);
            for (int i = -r; i <= r; ++i) {
                const float* row = in.data() + size_t(std::clamp(y + i, 0, h - 1)) * w;
                const float kk = k[i + r];
                for (int x = 0; x < w; ++x) acc[x] += kk * row[x];
            }
            std::copy(acc.begin(), acc.end(), out.begin() + size_t(y) * w);
        }
    });
}

// §6.2.1: linear RGB -> XYZ (D65).
void rgb_to_xyz(const float rgb[3], float xyz[3]) {
    const float a11 = 10135552.0f / 24577794.0f, a12 = 8788810.0f / 24577794.0f, a13 = 4435075.0f / 24577794.0f;
    const float a21 = 2613072.0f / 12288897.0f, a22 = 8788810.0f / 12288897.0f, a23 = 887015.0f / 12288897.0f;
    const float a31 = 1425312.0f / 73733382.0f, a32 = 8788810.0f / 73733382.0f, a33 = 70074185.0f / 73733382.0f;
    xyz[0] = a11 * rgb[0] + a12 * rgb[1] + a13 * rgb[2];
    xyz[1] = a21 * rgb[0] + a22 * rgb[1] + a23 * rgb[2];
    xyz[2] = a31 * rgb[0] + a32 * rgb[1] + a33 * rgb[2];
}

// §6.2.4: XYZ -> linear RGB.
void xyz_to_rgb(const float xyz[3], float rgb[3]) {
    rgb[0] = 3.241003275f * xyz[0] - 1.537398934f * xyz[1] - 0.498615861f * xyz[2];
    rgb[1] = -0.969224334f * xyz[0] + 1.875930071f * xyz[1] + 0.041554224f * xyz[2];
    rgb[2] = 0.055639423f * xyz[0] - 0.204011202f * xyz[1] + 1.057148933f * xyz[2];
}

// §6.2.4: CIELAB f(t).
float lab_f(float t) {
    const float delta = 6.0f / 29.0f;
    const float delta_sq = delta * delta;
    const float delta_cube = delta * delta_sq;
    return t > delta_cube ? std::pow(t, 1.0f / 3.0f) : t / (3.0f * delta_sq) + 4.0f / 29.0f;
}

// §6.2.4-5: linear RGB -> CIELAB -> Hunt-adjusted (a, b scaled by 0.01·L).
void rgb_to_hunt_lab(const float rgb[3], float lab[3]) {
    float xyz[3];
    rgb_to_xyz(rgb, xyz);
    const float fx = lab_f(xyz[0] * INV_WHITE[0]);
    const float fy = lab_f(xyz[1] * INV_WHITE[1]);
    const float fz = lab_f(xyz[2] * INV_WHITE[2]);
    lab[0] = 116.0f * fy - 16.0f;
    lab[1] = 0.01f * lab[0] * (500.0f * (fx - fy));
    lab[2] = 0.01f * lab[0] * (200.0f * (fy - fz));
}

float hyab(const float a[3], const float b[3]) {
    const float da = a[1] - b[1], db = a[2] - b[2];
    return std::fabs(a[0] - b[0]) + std::sqrt(da * da + db * db);
}

} // namespace

// CSF-filtered, Hunt-adjusted Lab planes and the feature magnitudes of one image (§6.2, §6.3).
struct FlipPrepared {
    Plane lab[3];
    Plane edge, point;
};

namespace {
using Prepared = FlipPrepared;

// out = sqrt(a^2 + b^2) per pixel (`out` already sized).
void magnitude(const Plane& a, const Plane& b, Plane& out, int w, int h) {
    parallel_rows(h, [&](int y0, int y1) {
        for (size_t i = size_t(y0) * w; i < size_t(y1) * w; ++i) out[i] = std::sqrt(a[i] * a[i] + b[i] * b[i]);
    });
}

// `rgb` is interleaved with `channels` floats per pixel; values are clamped to [0,1] (NaN -> 0).
Prepared prepare(const float* rgb, int channels, int w, int h, const FlipKernels& k) {
    const size_t n = size_t(w) * size_t(h);
    Plane ycc[3];
    for (auto& p : ycc) p.resize(n);
    parallel_rows(h, [&](int y0, int y1) {
        for (size_t i = size_t(y0) * w; i < size_t(y1) * w; ++i) {
            float c[3], xyz[3];
            for (int j = 0; j < 3; ++j) {
                const float v = rgb[i * channels + j];
                c[j] = v > 0.0f ? std::min(v, 1.0f) : 0.0f; // also maps NaN to 0
            }
            rgb_to_xyz(c, xyz);
            const float x = xyz[0] * INV_WHITE[0], y = xyz[1] * INV_WHITE[1], z = xyz[2] * INV_WHITE[2];
            ycc[0][i] = 116.0f * y - 16.0f; // §6.2.2: linear opponent space (no cube root)
            ycc[1][i] = 500.0f * (x - y);
            ycc[2][i] = 200.0f * (y - z);
        }
    });

    Prepared out;
    // §6.2.3 CSF: Y and Cx with their 1-D kernels; Cz as the sum of two separable Gaussians.
    Plane tmp, cz2;
    conv_x(ycc[0], tmp, w, h, k.y);
    conv_y(tmp, out.lab[0], w, h, k.y);
    conv_x(ycc[1], tmp, w, h, k.cx);
    conv_y(tmp, out.lab[1], w, h, k.cx);
    conv_x(ycc[2], tmp, w, h, k.cz1);
    conv_y(tmp, out.lab[2], w, h, k.cz1);
    conv_x(ycc[2], tmp, w, h, k.cz2);
    conv_y(tmp, cz2, w, h, k.cz2);
    parallel_rows(h, [&](int y0, int y1) {
        for (size_t i = size_t(y0) * w; i < size_t(y1) * w; ++i) {
            // §6.2.4: YCxCz -> XYZ -> linear RGB, clamp, -> Hunt-adjusted CIELAB.
            const float yy = (out.lab[0][i] + 16.0f) / 116.0f;
            const float cz = out.lab[2][i] + cz2[i];
            float xyz[3] = {(yy + out.lab[1][i] / 500.0f) * WHITE[0], yy * WHITE[1], (yy - cz / 200.0f) * WHITE[2]};
            float c[3], lab[3];
            xyz_to_rgb(xyz, c);
            for (float& v : c) v = std::clamp(v, 0.0f, 1.0f);
            rgb_to_hunt_lab(c, lab);
            for (int j = 0; j < 3; ++j) out.lab[j][i] = lab[j];
        }
    });

    // §6.3: features on the unfiltered, normalised achromatic channel.
    Plane& yhat = ycc[1]; // reuse storage
    parallel_rows(h, [&](int y0, int y1) {
        for (size_t i = size_t(y0) * w; i < size_t(y1) * w; ++i) yhat[i] = (ycc[0][i] + 16.0f) / 116.0f;
    });
    Plane gx, dx, ddx, a, b;
    conv_x(yhat, gx, w, h, k.g);
    conv_x(yhat, dx, w, h, k.dg);
    conv_x(yhat, ddx, w, h, k.ddg);
    conv_y(dx, a, w, h, k.g);  // edge x: G' along x, G along y
    conv_y(gx, b, w, h, k.dg); // edge y: G along x, G' along y
    out.edge.resize(n);
    magnitude(a, b, out.edge, w, h);
    conv_y(ddx, a, w, h, k.g);
    conv_y(gx, b, w, h, k.ddg);
    out.point.resize(n);
    magnitude(a, b, out.point, w, h);
    return out;
}

// LDR-FLIP map of two prepared images of the same size (§6.2.6-6.4).
std::vector<float> ldr_map(const Prepared& r, const Prepared& t, int w, int h) {
    // §6.2.7: the largest colour difference, green vs blue.
    float green[3] = {0.0f, 1.0f, 0.0f}, blue[3] = {0.0f, 0.0f, 1.0f}, lg[3], lb[3];
    rgb_to_hunt_lab(green, lg);
    rgb_to_hunt_lab(blue, lb);
    const float cmax = std::pow(hyab(lg, lb), QC);
    const float pccmax = PC * cmax;
    const float inv_sqrt2 = 1.0f / std::sqrt(2.0f);

    std::vector<float> map(size_t(w) * size_t(h));
    parallel_rows(h, [&](int y0, int y1) {
        for (size_t i = size_t(y0) * w; i < size_t(y1) * w; ++i) {
            const float a[3] = {r.lab[0][i], r.lab[1][i], r.lab[2][i]};
            const float b[3] = {t.lab[0][i], t.lab[1][i], t.lab[2][i]};
            const float de = std::pow(hyab(a, b), QC);
            const float dc =
                de < pccmax ? (PT / pccmax) * de : PT + ((de - pccmax) / (cmax - pccmax)) * (1.0f - PT);
            const float edge = std::fabs(r.edge[i] - t.edge[i]);
            const float point = std::fabs(r.point[i] - t.point[i]);
            const float df = std::pow(inv_sqrt2 * std::max(edge, point), QF);
            map[i] = std::pow(dc, 1.0f - df);
        }
    });
    return map;
}

// LDR-FLIP map of two interleaved RGB buffers of the same size (§6.2-6.4).
std::vector<float> ldr_map(const float* ref, int ref_channels, const float* test, int test_channels, int w, int h,
                           const FlipKernels& k) {
    return ldr_map(prepare(ref, ref_channels, w, h, k), prepare(test, test_channels, w, h, k), w, h);
}

// §5: float accumulation in row-major order, like the official tool's pooling<float>.
float float_mean(const std::vector<float>& v) {
    float sum = 0.0f;
    for (float x : v) sum += x;
    return v.empty() ? 0.0f : sum / float(v.size());
}

// A test image against a w x h reference.
void check_test(int w, int h, const Image& test) {
    if (test.empty()) throw Error("FLIP: empty image");
    if (w != test.width || h != test.height)
        throw Error(strfmt("FLIP: reference is %dx%d but test is %dx%d (sizes must match)", w, h, test.width,
                           test.height));
    if (test.channels < 3) throw Error("FLIP: images need 3 or 4 channels (RGB/RGBA)");
}

void check_pair(const Image& ref, const Image& test) {
    if (ref.empty()) throw Error("FLIP: empty image");
    check_test(ref.width, ref.height, test);
    if (ref.channels < 3) throw Error("FLIP: images need 3 or 4 channels (RGB/RGBA)");
}

} // namespace

float flip_ppd(float distance_m, float monitor_width_m, float resolution_x) {
    return distance_m * (resolution_x / monitor_width_m) * (PI / 180.0f);
}

FlipKernels flip_kernels(float ppd) {
    NBVH_CHECK(ppd > 0.0f && std::isfinite(ppd));
    FlipKernels k;
    // §6.2.3: radius from the widest Gaussian (b = 0.04), samples at i/PPD degrees.
    const float pi_sq = PI * PI;
    k.csf_radius = int(std::ceil(3.0f * std::sqrt(0.04f / (2.0f * pi_sq)) * ppd));
    const int cw = 2 * k.csf_radius + 1;
    auto gauss = [&](float t2, float a, float b) { return a * std::sqrt(PI / b) * std::exp(-pi_sq * t2 / b); };
    auto gauss_sqrt = [&](float t2, float a, float b) { return std::sqrt(a * std::sqrt(PI / b)) * std::exp(-pi_sq * t2 / b); };
    k.y.resize(cw), k.cx.resize(cw), k.cz1.resize(cw), k.cz2.resize(cw);
    float sy = 0.0f, scx = 0.0f, s1 = 0.0f, s2 = 0.0f;
    for (int i = 0; i < cw; ++i) {
        const float t = float(i - k.csf_radius) / ppd;
        const float t2 = t * t;
        sy += k.y[i] = gauss(t2, 1.0f, 0.0047f);
        scx += k.cx[i] = gauss(t2, 1.0f, 0.0053f);
        s1 += k.cz1[i] = gauss_sqrt(t2, 34.1f, 0.04f);
        s2 += k.cz2[i] = gauss_sqrt(t2, 13.5f, 0.025f);
    }
    const float cz_norm = 1.0f / std::sqrt(s1 * s1 + s2 * s2);
    for (int i = 0; i < cw; ++i) {
        k.y[i] /= sy;
        k.cx[i] /= scx;
        k.cz1[i] *= cz_norm;
        k.cz2[i] *= cz_norm;
    }

    // §6.3.2: feature Gaussian and derivatives.
    k.feature_sigma = 0.5f * GW * ppd;
    k.feature_radius = int(std::ceil(3.0f * k.feature_sigma));
    const int fw = 2 * k.feature_radius + 1;
    k.g.resize(fw), k.dg.resize(fw), k.ddg.resize(fw);
    float gs = 0.0f, dpos = 0.0f, dneg = 0.0f, ddpos = 0.0f, ddneg = 0.0f;
    const float s2sig = k.feature_sigma * k.feature_sigma;
    for (int i = 0; i < fw; ++i) {
        const float x = float(i - k.feature_radius);
        const float g = std::exp(-(x * x) / (2.0f * s2sig));
        const float dg = -x * g;
        const float ddg = (x * x / s2sig - 1.0f) * g;
        gs += g;
        (dg > 0.0f ? dpos : dneg) += std::fabs(dg);
        (ddg > 0.0f ? ddpos : ddneg) += std::fabs(ddg);
        k.g[i] = g, k.dg[i] = dg, k.ddg[i] = ddg;
    }
    for (int i = 0; i < fw; ++i) {
        k.g[i] /= gs;
        k.dg[i] /= k.dg[i] > 0.0f ? dpos : dneg;
        k.ddg[i] /= k.ddg[i] > 0.0f ? ddpos : ddneg;
    }
    return k;
}

FlipResult flip_ldr(const Image& reference, const Image& test, float ppd) {
    check_pair(reference, test); // before filtering the reference
    return FlipReference(reference, ppd).compare(test);
}

FlipReference::FlipReference(const Image& reference, float ppd) {
    if (reference.empty()) throw Error("FLIP: empty image");
    if (reference.channels < 3) throw Error("FLIP: images need 3 or 4 channels (RGB/RGBA)");
    if (!(ppd > 0.0f) || !std::isfinite(ppd)) throw Error(strfmt("FLIP: invalid pixels per degree %g", double(ppd)));
    width_ = reference.width;
    height_ = reference.height;
    kernels_ = std::make_shared<const FlipKernels>(flip_kernels(ppd));
    prepared_ = std::make_shared<const FlipPrepared>(
        prepare(reference.data.data(), reference.channels, width_, height_, *kernels_));
}

FlipResult FlipReference::compare(const Image& test) const {
    check_test(width_, height_, test);
    FlipResult res;
    res.width = width_;
    res.height = height_;
    res.error = ldr_map(*prepared_, prepare(test.data.data(), test.channels, width_, height_, *kernels_), width_,
                        height_);
    res.mean = float_mean(res.error);
    return res;
}

const float* flip_tone_map_coefficients(FlipToneMapper tm) {
    static const float aces[6] = {0.36f * 2.51f, 0.6f * 0.03f, 0.0f, 0.36f * 2.43f, 0.6f * 0.59f, 0.14f};
    static const float hable[6] = {0.231683f, 0.013791f, 0.0f, 0.18f, 0.3f, 0.018f};
    static const float reinhard[6] = {0.0f, 1.0f, 0.0f, 0.0f, 1.0f, 1.0f};
    switch (tm) {
    case FlipToneMapper::aces: return aces;
    case FlipToneMapper::hable: return hable;
    case FlipToneMapper::reinhard: return reinhard;
    }
    return aces;
}

float flip_tone_map_x_max(FlipToneMapper tm) {
    const float* k = flip_tone_map_coefficients(tm);
    const float t = 0.85f;
    const float a = k[0] - t * k[3], b = k[1] - t * k[4], c = k[2] - t * k[5];
    if (a == 0.0f) return -c / b;
    const float d1 = -0.5f * (b / a);
    const float d2 = std::sqrt(d1 * d1 - c / a);
    return d1 + d2;
}

void flip_tone_map(FlipToneMapper tm, float rgb[3]) {
    if (tm == FlipToneMapper::reinhard) {
        const float l = 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
        for (int c = 0; c < 3; ++c) rgb[c] = rgb[c] / (1.0f + l);
        return;
    }
    const float* k = flip_tone_map_coefficients(tm);
    for (int c = 0; c < 3; ++c) {
        const float x = rgb[c], x2 = x * x;
        rgb[c] = (x2 * k[0] + x * k[1] + k[2]) / (x2 * k[3] + x * k[4] + k[5]);
    }
}

FlipExposureRange flip_exposure_range(const Image& reference, FlipToneMapper tm) {
    NBVH_CHECK(reference.channels >= 3);
    const size_t n = reference.pixel_count();
    std::vector<float> lum(n);
    float smallest_positive = 3.4e38f;
    for (size_t i = 0; i < n; ++i) {
        const float* p = reference.data.data() + i * size_t(reference.channels);
        lum[i] = 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2];
        if (lum[i] > 0.0f) smallest_positive = std::min(smallest_positive, lum[i]);
    }
    std::sort(lum.begin(), lum.end());
    const float y_max = lum.empty() ? 0.0f : lum.back();
    if (!(y_max > 0.0f) || !std::isfinite(y_max))
        throw Error("HDR-FLIP: the reference has no positive finite luminance, the exposure range is undefined");
    float y_median = lum[n / 2];
    if (!(y_median > 0.0f)) y_median = smallest_positive; // official tool would divide by zero here
    const float x_max = flip_tone_map_x_max(tm);
    FlipExposureRange r;
    r.start = std::log2(x_max / y_max);
    r.stop = std::log2(x_max / y_median);
    r.count = std::max(2, int(std::ceil(r.stop - r.start)));
    if (r.count > 64) {
        log_warn("HDR-FLIP: %d exposures needed for the reference's range; capping at 64", r.count);
        r.count = 64;
    }
    return r;
}

FlipResult flip_hdr(const Image& reference, const Image& test, float ppd, const HdrFlipOptions& options) {
    check_pair(reference, test);
    if (!(ppd > 0.0f) || !std::isfinite(ppd)) throw Error(strfmt("FLIP: invalid pixels per degree %g", double(ppd)));
    // Non-finite samples would poison the tone mapper (inf/inf); make them finite first.
    Image ref = reference, tst = test;
    const size_t bad = sanitize_non_finite(ref) + sanitize_non_finite(tst);
    if (bad) log_warn("HDR-FLIP: replaced %zu non-finite samples (NaN/-Inf -> 0, +Inf -> 65504)", bad);

    FlipExposureRange range;
    if (!options.start_exposure || !options.stop_exposure) {
        range = flip_exposure_range(ref, options.tone_mapper);
    }
    if (options.start_exposure) range.start = *options.start_exposure;
    if (options.stop_exposure) range.stop = *options.stop_exposure;
    if (!(range.start <= range.stop))
        throw Error(strfmt("HDR-FLIP: start exposure %g is above stop exposure %g", double(range.start), double(range.stop)));
    range.count = std::min(64, std::max(2, int(std::ceil(range.stop - range.start))));

    const FlipKernels k = flip_kernels(ppd);
    FlipResult res;
    res.width = ref.width;
    res.height = ref.height;
    res.exposure_count = range.count;
    res.start_exposure = range.start;
    res.stop_exposure = range.stop;
    const size_t n = ref.pixel_count();
    res.error.assign(n, 0.0f);
    res.exposure_map.assign(n, 0.0f);
    const float step = (range.stop - range.start) / float(range.count - 1);
    std::vector<float> r3(n * 3), t3(n * 3);
    for (int e = 0; e < range.count; ++e) {
        const float scale = std::pow(2.0f, range.start + float(e) * step);
        // §6.4.3: expose, tone-map, clamp; the result is used as linear RGB.
        auto expose = [&](const Image& src, std::vector<float>& dst) {
            for (size_t i = 0; i < n; ++i) {
                const float* p = src.data.data() + i * size_t(src.channels);
                float c[3] = {p[0] * scale, p[1] * scale, p[2] * scale};
                flip_tone_map(options.tone_mapper, c);
                for (int j = 0; j < 3; ++j) dst[i * 3 + j] = std::clamp(c[j], 0.0f, 1.0f);
            }
        };
        expose(ref, r3);
        expose(tst, t3);
        const std::vector<float> map = ldr_map(r3.data(), 3, t3.data(), 3, res.width, res.height, k);
        const float level = float(e) / float(range.count - 1);
        for (size_t i = 0; i < n; ++i) {
            if (map[i] > res.error[i]) {
                res.error[i] = map[i];
                res.exposure_map[i] = level;
            }
        }
    }
    res.mean = float_mean(res.error);
    return res;
}

std::vector<uint8_t> flip_heatmap_rgb8(const FlipResult& result) {
    // matplotlib "magma" at 0, 1/8, ..., 1 (sRGB).
    static const uint8_t stops[9][3] = {{0, 0, 4},      {29, 17, 71},   {81, 18, 124},  {130, 38, 129}, {182, 54, 121},
                                        {230, 81, 100}, {251, 136, 97}, {254, 194, 135}, {252, 253, 191}};
    std::vector<uint8_t> out(result.error.size() * 3);
    for (size_t i = 0; i < result.error.size(); ++i) {
        const float v = result.error[i];
        const int idx = std::clamp(int(std::lround((v > 0.0f ? std::min(v, 1.0f) : 0.0f) * 255.0f)), 0, 255);
        const float f = float(idx) / 255.0f * 8.0f;
        const int s = std::min(7, int(f));
        const float t = f - float(s);
        for (int c = 0; c < 3; ++c)
            out[i * 3 + c] = uint8_t(std::lround(float(stops[s][c]) * (1.0f - t) + float(stops[s + 1][c]) * t));
    }
    return out;
}

void save_flip_heatmap(const std::string& path, const FlipResult& result) {
    const std::vector<uint8_t> px = flip_heatmap_rgb8(result);
    save_png_8bit(path, result.width, result.height, 3, px.data());
}

} // namespace nbvh
