// Segment encoding (entry/middle/exit, reversal), zero-extent guard, extreme scales and decode rules.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "shaders/shared/neural_query.h"

namespace {
bool finite3(vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
} // namespace

TEST(NeuralQuery, EncodingBoxAndPoint) {
    const GpuEncodingBox b = nb_make_encoding_box(vec3(-1.0f, 0.0f, 2.0f), vec3(1.0f, 4.0f, 3.0f));
    EXPECT_FLOAT_EQ(b.center.x, 0.0f);
    EXPECT_FLOAT_EQ(b.center.y, 2.0f);
    EXPECT_FLOAT_EQ(b.center.z, 2.5f);
    EXPECT_FLOAT_EQ(b.extent.x, 2.0f * 1.00011f);
    EXPECT_FLOAT_EQ(b.extent.y, 4.0f * 1.00011f);
    EXPECT_FLOAT_EQ(b.extent.z, 1.0f * 1.00011f);
    EXPECT_FLOAT_EQ(b.depth_pad, 1e-3f);
    EXPECT_FLOAT_EQ(b.fixed_depth_eps, 1e-5f);
    // the box corners map just inside [0,1] (anisotropic, per axis)
    const vec3 lo = nb_encode_point(b, vec3(-1.0f, 0.0f, 2.0f));
    const vec3 hi = nb_encode_point(b, vec3(1.0f, 4.0f, 3.0f));
    EXPECT_NEAR(lo.x, 0.5f - 0.5f / 1.00011f, 1e-6f);
    EXPECT_NEAR(hi.y, 0.5f + 0.5f / 1.00011f, 1e-6f);
    EXPECT_GT(lo.z, 0.0f);
    EXPECT_LT(hi.z, 1.0f);
    const vec3 c = nb_encode_point(b, vec3(0.0f, 2.0f, 2.5f));
    EXPECT_FLOAT_EQ(c.x, 0.5f);
    EXPECT_FLOAT_EQ(c.y, 0.5f);
}

TEST(NeuralQuery, EntryMiddleExitForward) {
    const GpuEncodingBox b = nb_make_encoding_box(vec3(0.0f), vec3(1.0f));
    vec3 p0, p1, p2;
    // ray along +x through the unit box from x = -1: entry t = 1.25, exit t = 1.75 (leaf [0.25,0.75])
    const bool rev = nb_segment_points(b, vec3(-1.0f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), 1.25f, 1.75f, p0, p1, p2);
    EXPECT_FALSE(rev);
    const float s = 1.0f / 1.00011f;
    EXPECT_NEAR(p0.x, 0.5f + (0.25f - 0.5f) * s, 1e-6f);
    EXPECT_NEAR(p1.x, 0.5f, 1e-6f);
    EXPECT_NEAR(p2.x, 0.5f + (0.75f - 0.5f) * s, 1e-6f);
    EXPECT_FLOAT_EQ(p0.y, 0.5f);
    EXPECT_FLOAT_EQ(p1.z, 0.5f);
}

TEST(NeuralQuery, OriginInsideLeafReversesSegment) {
    const GpuEncodingBox b = nb_make_encoding_box(vec3(0.0f), vec3(1.0f));
    vec3 f0, f1, f2, r0, r1, r2;
    // origin at x = 0.4 inside leaf [0.2, 0.8] (t_entry = -0.2 < 0): query runs exit -> entry
    const bool rev = nb_segment_points(b, vec3(0.4f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), -0.2f, 0.4f, r0, r1, r2);
    EXPECT_TRUE(rev);
    nb_segment_points(b, vec3(0.0f, 0.5f, 0.5f), vec3(1.0f, 0.0f, 0.0f), 0.2f, 0.8f, f0, f1, f2);
    EXPECT_NEAR(r0.x, f2.x, 1e-6f); // reversed start = forward exit (x = 0.8)
    EXPECT_NEAR(r2.x, f0.x, 1e-6f);
    EXPECT_NEAR(r1.x, f1.x, 1e-6f);
    // origin exactly on the entry face (t_entry = 0) is NOT inside
    EXPECT_FALSE(nb_query_reversed(0.0f));
    EXPECT_TRUE(nb_query_reversed(-1e-30f));
}

TEST(NeuralQuery, DecodeDepthOutsideAndInside) {
    const GpuEncodingBox b = nb_make_encoding_box(vec3(0.0f), vec3(1.0f));
    float t = 0.0f;
    // outside: t = t_entry + u (L + 1e-3)
    EXPECT_TRUE(nb_decode_depth(b, 0.5f, 2.0f, 4.0f, 1.0f, t));
    EXPECT_FLOAT_EQ(t, 2.0f + 0.5f * 2.001f);
    EXPECT_TRUE(nb_decode_depth(b, 1.7f, 2.0f, 4.0f, 1.0f, t)); // u clamped to 1
    EXPECT_FLOAT_EQ(t, 2.0f + 2.001f);
    EXPECT_TRUE(nb_decode_depth(b, std::nanf(""), 2.0f, 4.0f, 1.0f, t)); // NaN -> u = 0, no NaN out
    EXPECT_FLOAT_EQ(t, 2.0f);
    // inside: t_entry = -1, t_exit = 1, L = 2; d = u * 2.001 measured back from the exit;
    // accepted iff d < 1 - 0.2 * 2 - 1e-5 = 0.59999
    EXPECT_TRUE(nb_decode_depth(b, 0.25f, -1.0f, 1.0f, 1.0f, t)); // d = 0.50025
    EXPECT_FLOAT_EQ(t, 1.0f - 0.25f * 2.001f);
    EXPECT_FALSE(nb_decode_depth(b, 0.3f, -1.0f, 1.0f, 1.0f, t)); // d = 0.6003 -> too close to the origin
    EXPECT_FLOAT_EQ(t, 1.0f - 0.3f * 2.001f);
    // target encoding inverts the decode
    const float u = nb_encode_depth_target(b, 3.0f, 2.0f, 4.0f, false);
    EXPECT_TRUE(nb_decode_depth(b, u, 2.0f, 4.0f, 1.0f, t));
    EXPECT_NEAR(t, 3.0f, 1e-6f);
    EXPECT_NEAR(nb_encode_depth_target(b, 0.5f, -1.0f, 1.0f, true), 0.5f / 2.001f, 1e-7f);
}

TEST(NeuralQuery, DecodeVisibilityAndNormal) {
    EXPECT_TRUE(nb_decode_visibility(0.51f, NB_VISIBILITY_THRESHOLD));
    EXPECT_FALSE(nb_decode_visibility(0.5f, NB_VISIBILITY_THRESHOLD)); // strictly greater
    EXPECT_FALSE(nb_decode_visibility(std::nanf(""), NB_VISIBILITY_THRESHOLD));
    vec3 n = nb_decode_normal(1.0f, 0.5f, 0.5f);
    EXPECT_FLOAT_EQ(n.x, 1.0f);
    EXPECT_FLOAT_EQ(n.y, 0.0f);
    // linearised outputs (0.45..0.55) decode to the same direction: 2y - 1 = n / 10
    n = nb_decode_normal(0.5f, 0.5f - 0.05f * 0.6f, 0.5f + 0.05f * 0.8f);
    EXPECT_NEAR(n.y, -0.6f, 1e-4f);
    EXPECT_NEAR(n.z, 0.8f, 1e-4f);
    n = nb_decode_normal(0.5f, 0.5f, 0.5f); // degenerate -> +z, not NaN
    EXPECT_FLOAT_EQ(n.z, 1.0f);
}

TEST(NeuralQuery, ZeroExtentAssetsAreGuarded) {
    // flat asset (zero extent in y), a line (zero in y and z), a point (all zero)
    const vec3 los[3] = {vec3(0.0f, 1.0f, 0.0f), vec3(0.0f, 1.0f, 1.0f), vec3(3.0f, 1.0f, 1.0f)};
    const vec3 his[3] = {vec3(2.0f, 1.0f, 2.0f), vec3(2.0f, 1.0f, 1.0f), vec3(3.0f, 1.0f, 1.0f)};
    for (int i = 0; i < 3; ++i) {
        const GpuEncodingBox b = nb_make_encoding_box(los[i], his[i]);
        EXPECT_GT(b.extent.x, 0.0f);
        EXPECT_GT(b.extent.y, 0.0f);
        EXPECT_GT(b.extent.z, 0.0f);
        // the guard: at least 1e-3 of the largest extent
        if (i < 2) {
            EXPECT_GE(b.extent.y, 2.0f * 1e-3f);
        }
        const vec3 e = nb_encode_point(b, vec3(1.0f, 1.0f, 1.0f));
        EXPECT_TRUE(finite3(e));
        vec3 p0, p1, p2;
        nb_segment_points(b, vec3(1.0f, 5.0f, 1.0f), vec3(0.0f, -1.0f, 0.0f), 4.0f, 4.0f, p0, p1, p2);
        EXPECT_TRUE(finite3(p0) && finite3(p1) && finite3(p2));
        EXPECT_NEAR(p1.y, 0.5f, 1e-5f); // the flat plane is the centre of the padded axis
    }
}

TEST(NeuralQuery, ExtremeScalesAndBadIntervalsGiveFiniteInputs) {
    const float inf = std::numeric_limits<float>::infinity();
    struct Case { vec3 lo, hi; };
    const Case cases[] = {
        {vec3(0.0f), vec3(1e-3f)},                                      // tiny asset
        {vec3(-1e5f), vec3(1e5f)},                                      // huge asset
        {vec3(1e5f, 1e5f, 1e5f), vec3(1e5f + 1.0f, 1e5f, 1e5f + 1.0f)}, // far and flat
        {vec3(-3e7f), vec3(-3e7f + 1e-3f)},                             // far and tiny
    };
    for (const Case& c : cases) {
        const GpuEncodingBox b = nb_make_encoding_box(c.lo, c.hi);
        EXPECT_TRUE(finite3(b.extent) && finite3(b.center));
        const vec3 mid = (c.lo + c.hi) * 0.5f;
        const vec3 dirs[3] = {vec3(1.0f, 0.0f, 0.0f), vec3(0.0f, 0.0f, -1.0f), vec3(0.57735f)};
        // intervals a traversal may hand over: normal, empty, origin on a face, parallel (+-inf), NaN
        const float ts[][2] = {{0.0f, 1e-3f}, {-1e-3f, 1e-3f}, {0.0f, 0.0f}, {-inf, inf}, {std::nanf(""), 1.0f}};
        for (const vec3& d : dirs)
            for (const auto& t : ts) {
                vec3 p0, p1, p2;
                nb_segment_points(b, mid, d, t[0], t[1], p0, p1, p2);
                EXPECT_TRUE(finite3(p0) && finite3(p1) && finite3(p2));
                EXPECT_GE(p0.x, NB_ENC_CLAMP_LO);
                EXPECT_LE(p2.z, NB_ENC_CLAMP_HI);
                float th = 0.0f;
                nb_decode_depth(b, 0.5f, t[0], t[1], 1.0f, th);
                if (std::isfinite(t[0]) && std::isfinite(t[1])) {
                    EXPECT_TRUE(std::isfinite(th));
                }
            }
    }
}

// The depth decode is the same hit at every instance scale: a leaf segment of object length L with the
// network's u decodes to the same object-space point whether the ray's object-space direction has length
// 1 (training) or k (the renderer's rays: 1 / the instance's scale; Chess pieces are ~20, a 1e4 m asset
// 1e-4), forward and with the origin inside the leaf (reversed), and the inside-origin margin accepts or
// rejects alike. Before the pads were converted by 1 / |dir| a 5 cm piece decoded hits up to 20 % of its
// leaf deeper than trained.
TEST(NeuralQuery, DepthDecodeIsTheSameHitAtEveryInstanceScale) {
    const GpuEncodingBox b = nb_make_encoding_box(vec3(-1.0f), vec3(1.0f));
    const float lengths[] = {1.0e-3f, 0.02f, 0.5f};
    const float us[] = {0.0f, 0.1f, 0.5f, 0.93f, 1.0f};
    const float scales[] = {1.0e-4f, 0.05f, 1.0f, 20.0f, 1.0e4f};
    for (float len : lengths)
        for (float u : us)
            for (float entry_frac : {0.3f, -0.4f}) { // forward, and the origin 40 % into the leaf
                const float te = entry_frac * len, tx = te + len; // unit direction: t in object units
                float t1;
                const bool acc1 = nb_decode_depth(b, u, te, tx, 1.0f, t1);
                for (float k : scales) {
                    float tk;
                    const bool acck = nb_decode_depth(b, u, te / k, tx / k, k, tk);
                    EXPECT_EQ(acck, acc1) << "len " << len << " u " << u << " k " << k;
                    EXPECT_NEAR(tk * k, t1, 2e-6f * (std::abs(t1) + len)) << "len " << len << " u " << u << " k " << k;
                }
            }
    float t;
    EXPECT_TRUE(nb_decode_depth(b, 0.5f, 2.0f, 4.0f, 0.0f, t)); // a zero length counts as 1
    EXPECT_FLOAT_EQ(t, 2.0f + 0.5f * (2.0f + b.depth_pad));
    EXPECT_TRUE(nb_decode_depth(b, 0.5f, 2.0f, 4.0f, std::nanf(""), t));
    EXPECT_TRUE(std::isfinite(t));
}

// Back-face escape (neural_query.h nb_backface_skip): which hits a ray leaving a back-facing neural hit
// skips. Hard cases: grazing normals either side of the cosine, degenerate and non-finite vectors (the
// hit is kept: the previous behaviour), object-space directions of tiny and huge instance scales.
TEST(NeuralQuery, BackfaceEscapeSkipsOnlyClearBackFaces) {
    const vec3 d(0.0f, 0.0f, 1.0f);
    const float c = NB_BACKFACE_ESCAPE_COS;
    const float s = std::sqrt(1.0f - c * c);
    // flagged path ray, reversed query (the leaf it starts in): back faces beyond the cosine are skipped
    EXPECT_TRUE(nb_backface_skip(true, false, true, vec3(0.0f, 0.0f, 1.0f), d));
    EXPECT_TRUE(nb_backface_skip(true, false, true, vec3(s * 0.99f, 0.0f, c * 1.01f), d));
    EXPECT_FALSE(nb_backface_skip(true, false, true, vec3(s * 1.01f, 0.0f, c * 0.99f), d)); // grazing: kept
    EXPECT_FALSE(nb_backface_skip(true, false, true, vec3(1.0f, 0.0f, 0.0f), d));             // perpendicular
    EXPECT_FALSE(nb_backface_skip(true, false, true, vec3(0.0f, 0.0f, -1.0f), d));            // front face
    // path rays keep back faces of later leaves (forward queries); shadow rays skip them in every leaf
    EXPECT_FALSE(nb_backface_skip(true, false, false, vec3(0.0f, 0.0f, 1.0f), d));
    EXPECT_TRUE(nb_backface_skip(true, true, false, vec3(0.0f, 0.0f, 1.0f), d));
    EXPECT_TRUE(nb_backface_skip(true, true, true, vec3(0.0f, 0.0f, 1.0f), d));
    // unflagged rays skip nothing
    EXPECT_FALSE(nb_backface_skip(false, true, true, vec3(0.0f, 0.0f, 1.0f), d));
    // lengths do not matter (decoded normals are unit, object-space directions are 1 / instance scale)
    for (float scale : {1e-4f, 1e-2f, 1.0f, 1e2f, 1e4f}) {
        const vec3 ds = d * scale;
        EXPECT_TRUE(nb_backface_skip(true, true, true, vec3(s * 0.99f, 0.0f, c * 1.01f), ds)) << scale;
        EXPECT_FALSE(nb_backface_skip(true, true, true, vec3(s * 1.01f, 0.0f, c * 0.99f), ds)) << scale;
        EXPECT_TRUE(nb_faces_along(vec3(0.0f, 0.0f, 1.0f) * 0.5f, ds, 0.0f)) << scale;
    }
    // degenerate and non-finite: never a skip
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_FALSE(nb_backface_skip(true, true, true, vec3(0.0f), d));
    EXPECT_FALSE(nb_backface_skip(true, true, true, vec3(0.0f, 0.0f, 1.0f), vec3(0.0f)));
    EXPECT_FALSE(nb_backface_skip(true, true, true, vec3(nan, 0.0f, 1.0f), d));
    EXPECT_FALSE(nb_backface_skip(true, true, true, vec3(0.0f, 0.0f, 1.0f), vec3(0.0f, 0.0f, inf)));
    EXPECT_FALSE(nb_backface_skip(true, true, true, vec3(0.0f, 0.0f, 1.0f), vec3(0.0f, 0.0f, 1e30f)));
    // the flag test of the shade pass (cosine 0): any predicted normal along the ray
    EXPECT_TRUE(nb_faces_along(vec3(1.0f, 0.0f, 1e-3f), d, 0.0f));
    EXPECT_FALSE(nb_faces_along(vec3(1.0f, 0.0f, 0.0f), d, 0.0f));
    EXPECT_FALSE(nb_faces_along(vec3(1.0f, 0.0f, -1e-3f), d, 0.0f));
}
