#include "tools/render/raytracer.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kernels/parallel.hpp"
#include "tools/render/hash.hpp"
#include "tools/render/indenter_mesh.hpp"
#include "tools/render/print.hpp"
#include "tools/render/quads.hpp"

namespace papertear::render {

namespace {

using Vec3 = Eigen::Vector3f;

constexpr int kTile = 32;
constexpr int kMaxLayersCrossed = 16;  // translucent surfaces a ray may pass before it stops
constexpr float kFibreWrap = 0.5f;     // how far round a fibre the key light reaches

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
float linear_to_srgb(float c) { return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }
Vec3 linear_colour(const Vec3d& srgb) {
  return {srgb_to_linear(float(srgb[0])), srgb_to_linear(float(srgb[1])), srgb_to_linear(float(srgb[2]))};
}
Vec3 vec(const Vec3f& a) { return {a[0], a[1], a[2]}; }

// Linear-light texture with bilinear lookups; (0, 0) is the image's top-left corner.
class Texture {
 public:
  Texture() = default;
  explicit Texture(const Image& srgb) : w_(srgb.width), h_(srgb.height), texels_(srgb.rgb.size()) {
    std::array<float, 256> lut{};
    for (int i = 0; i < 256; ++i) lut[std::size_t(i)] = srgb_to_linear(float(i) / 255.0f);
    for (std::size_t i = 0; i < srgb.rgb.size(); ++i) texels_[i] = lut[srgb.rgb[i]];
  }
  Vec3 sample(float s, float t) const {
    const float x = std::clamp(s * float(w_) - 0.5f, 0.0f, float(w_ - 1));
    const float y = std::clamp(t * float(h_) - 0.5f, 0.0f, float(h_ - 1));
    const int x0 = int(x), y0 = int(y);
    const int x1 = std::min(x0 + 1, w_ - 1), y1 = std::min(y0 + 1, h_ - 1);
    const float fx = x - float(x0), fy = y - float(y0);
    return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x1, y0)) + fy * ((1 - fx) * at(x0, y1) + fx * at(x1, y1));
  }

 private:
  Vec3 at(int x, int y) const {
    const float* p = texels_.data() + (std::size_t(y) * std::size_t(w_) + std::size_t(x)) * 3;
    return {p[0], p[1], p[2]};
  }
  int w_ = 0, h_ = 0;
  std::vector<float> texels_;
};

// Linear [0, 1] to 8-bit sRGB through a table fine enough that no two neighbouring 8-bit
// codes are skipped.
class SrgbEncoder {
 public:
  SrgbEncoder() {
    for (int i = 0; i <= kSteps; ++i)
      lut_[std::size_t(i)] = std::uint8_t(std::lround(255.0f * linear_to_srgb(float(i) / float(kSteps))));
  }
  std::uint8_t operator()(float linear) const {
    const float c = std::clamp(linear, 0.0f, 1.0f);
    // std::lround for x >= 0 without the library call (three per pixel): x - trunc(x) is
    // exact, so this rounds halves up exactly as lround does.
    const float x = c * float(kSteps);
    const auto i = std::size_t(x);
    return lut_[i + std::size_t(x - float(i) >= 0.5f)];
  }

 private:
  static constexpr int kSteps = 8192;
  std::array<std::uint8_t, kSteps + 1> lut_{};
};

// A scene with at most one geometry (id 0), kept from frame to frame: rebuilding a live
// scene reuses its BVH's memory blocks, where a fresh scene allocates (and faults in) new ones.
struct EmbreeScene {
  RTCScene scene = nullptr;
  RTCGeometry geometry = nullptr;  // attached as id 0, or none
  explicit EmbreeScene(RTCDevice device) : scene(rtcNewScene(device)) {}
  ~EmbreeScene() {
    if (geometry) rtcReleaseGeometry(geometry);
    if (scene) rtcReleaseScene(scene);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // The scene's geometry, a new one of `type` attached if it has none.
  RTCGeometry use_geometry(RTCDevice device, RTCGeometryType type) {
    if (!geometry) {
      geometry = rtcNewGeometry(device, type);
      rtcAttachGeometryByID(scene, geometry, 0);
    }
    return geometry;
  }
  void drop_geometry() {
    if (!geometry) return;
    rtcDetachGeometry(scene, 0);
    rtcReleaseGeometry(geometry);
    geometry = nullptr;
  }
};

void check_device(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE) throw RenderError(std::string("Embree: ") + what + " failed (error " + std::to_string(int(e)) + ")");
}

// Materials of one frame, in linear light.
struct Look {
  Vec3 background, paper;
  Vec3 to_light;          // unit, towards the light
  Vec3 light_u, light_v;  // spanning the light's disc
  float softness, intensity, ambient, exposure;
  bool print_enabled;
};

const RenderSettings& checked(const RenderSettings& s) {
  validate(s);
  return s;
}

}  // namespace

namespace {

// Rays traced together as one Embree packet.
constexpr int kPacket = 16;
struct PacketRays {
  std::array<Vec3, kPacket> dir;
  std::array<std::uint64_t, kPacket> key;
  // The pixel and sample of each ray, from which PixelSampler::aim() sets dir and key.
  std::array<int, kPacket> x{}, y{}, sample{};
  int count = 0;
};

// Sub-pixel position of sample s: the R2 sequence (a low-discrepancy rank-1 lattice), shifted
// per pixel by a hashed offset so neighbouring pixels do not share a pattern. Inline, so that
// PixelSampler::aim() vectorises.
[[gnu::always_inline]] inline std::array<float, 2> subpixel(int x, int y, int s) {
  HashStream rng(hash_key(std::uint64_t(x), std::uint64_t(y), 0x7069786c));
  const float ox = rng.uniform(), oy = rng.uniform();
  const float gx = 0.7548776662f * float(s) + ox, gy = 0.5698402910f * float(s) + oy;
  // gx, gy >= 0, so truncation is floor: the same values, but the loop in aim_lanes()
  // vectorises, which it does not with std::floor (GCC 12 vectorises floorf only without
  // -ftrapping-math).
  return {gx - float(int(gx)), gy - float(int(gy))};
}

// Pixels x0..x1 by y0..y1 (none by default).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool contains(int x, int y) const { return x >= x0 && x <= x1 && y >= y0 && y <= y1; }
};

// Primary rays of one frame.
class PixelSampler {
 public:
  PixelSampler(const Camera& c, int width, int height, int samples)
      : eye_(vec(c.position)), fwd_(vec(c.forward)), right_(vec(c.right)), up_(vec(c.up)),
        ty_(c.tan_half_fov_y), tx_(c.tan_half_fov_y * c.aspect), width_(width), height_(height), samples_(samples) {}

  const Vec3& eye() const { return eye_; }

  // Adds sample k of pixel (x, y) to a packet; aim() then sets its ray.
  static void add(PacketRays& rays, int x, int y, int k) {
    const auto i = std::size_t(rays.count++);
    rays.x[i] = x;
    rays.y[i] = y;
    rays.sample[i] = k;
  }

  // The directions and keys of a packet's rays.
  void aim(PacketRays& rays) const {
    if (samples_ == 1)
      aim_lanes<true>(rays);
    else
      aim_lanes<false>(rays);
  }

  // The pixels whose rays may meet the box from corner `lo` to corner `hi` (with a margin of
  // two pixels): where its corners' images fall, or every pixel if one of them is not in
  // front of the eye. A box is convex, so its image lies within its corners'.
  PixelRect covering(const Vec3& lo, const Vec3& hi) const {
    if (!(lo.array() <= hi.array()).all()) return {};
    const PixelRect all{std::numeric_limits<int>::min(), std::numeric_limits<int>::min(),
                        std::numeric_limits<int>::max(), std::numeric_limits<int>::max()};
    constexpr float kInf = std::numeric_limits<float>::infinity();
    float left = kInf, top = kInf, right = -kInf, bottom = -kInf;
    for (int c = 0; c < 8; ++c) {
      const Vec3 d = Vec3(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(), c & 4 ? hi.z() : lo.z()) - eye_;
      const float depth = d.dot(fwd_);
      if (!(depth > 1e-3f * d.norm())) return all;
      // The ray through (x, y) points along fwd + ndc_x right + ndc_y up (aim_lane).
      const float x = 0.5f * float(width_) * (d.dot(right_) / (depth * tx_) + 1.0f);
      const float y = 0.5f * float(height_) * (1.0f - d.dot(up_) / (depth * ty_));
      left = std::min(left, x);
      right = std::max(right, x);
      top = std::min(top, y);
      bottom = std::max(bottom, y);
    }
    const auto pixel = [](float v, int size) { return int(std::floor(std::clamp(v, -4.0f, float(size) + 4.0f))); };
    return {pixel(left, width_) - 2, pixel(top, height_) - 2, pixel(right, width_) + 2, pixel(bottom, height_) + 2};
  }

 private:
  // All kPacket lanes, in plain arrays: a fixed-length loop over one lane's branch-free
  // scalar code is what the compiler turns into vector code (hashes, divisions and square
  // roots 16 at a time instead of one after another). Whether rays go through the pixel
  // centres is a template parameter, not a branch in the loop, for the same reason.
  template <bool kCentred>
  void aim_lanes(PacketRays& rays) const {
    alignas(64) std::array<float, kPacket> dx, dy, dz;
    for (std::size_t i = 0; i < kPacket; ++i) {
      aim_lane<kCentred>(rays.x[i], rays.y[i], rays.sample[i], dx[i], dy[i], dz[i]);
      rays.key[i] = hash_key(std::uint64_t(rays.x[i]), std::uint64_t(rays.y[i]), std::uint64_t(rays.sample[i]));
    }
    for (std::size_t i = 0; i < std::size_t(rays.count); ++i) rays.dir[i] = {dx[i], dy[i], dz[i]};
  }

  // The unit direction of sample k of pixel (x, y), in the same operations and order as
  // Eigen's (fwd + nx right + ny up).normalized().
  template <bool kCentred>
  [[gnu::always_inline]] void aim_lane(int x, int y, int k, float& dx, float& dy, float& dz) const {
    const auto off = kCentred ? std::array<float, 2>{0.5f, 0.5f} : subpixel(x, y, k);
    const float ndc_x = (2.0f * (float(x) + off[0]) / float(width_) - 1.0f) * tx_;
    const float ndc_y = (1.0f - 2.0f * (float(y) + off[1]) / float(height_)) * ty_;
    dx = fwd_[0] + ndc_x * right_[0] + ndc_y * up_[0];
    dy = fwd_[1] + ndc_x * right_[1] + ndc_y * up_[1];
    dz = fwd_[2] + ndc_x * right_[2] + ndc_y * up_[2];
    const float len = std::sqrt(dx * dx + dy * dy + dz * dz);
    dx /= len;
    dy /= len;
    dz /= len;
  }

 private:
  Vec3 eye_, fwd_, right_, up_;
  float ty_, tx_;
  int width_, height_, samples_;
};

// The surfaces are split into Embree scenes: opaque triangles and peeled skins. A ray finds
// its nearest opaque surface once, in the big scene, and gathers the few skins in front of
// it in a small one; a shadow ray asks the big scene only whether anything opaque is in the
// way (an any-hit query, which stops at the first hit) and gathers the skins only if not.
//
// Each scene holds only the triangles its rays can need:
// - Skins count only where a ray enters them (gather_entering), so there are two skin
//   scenes: one for primary rays with the skin triangles facing the eye (for rays from one
//   point the test per triangle is exact), one for shadow rays with those turned away from
//   some point of the light's disc. The same hits as with all skin triangles.
// - A fibre tooth is a closed pyramid on its torn face, itself part of a cell's closed
//   surface: a ray from outside meets a side facing it first, and a shadow ray through one
//   leaves through a side turned towards the light. Triangles of fibre material (tooth
//   sides and the torn faces they stand on) turned away from the eye and from every point
//   of the light's disc are left out of the opaque scene (one scene for both kinds of rays:
//   two, each with only its own sides, trace no faster and take twice as long to build).
//   The other faces of the sheet all stay: where an opaque cell is joined to a peeled skin
//   no face is drawn between them, and a ray through the skin may see the inside of the
//   opaque surface (culling them changed 949 pixels of the bench's torn frame, this 338).
// About 40 % of the fibre triangles (the bulk of a torn frame's triangles) and half of
// the skin triangles drop out of each scene, and with them many of the overlapping slivers
// that make fringes slow to trace.
enum SceneId : unsigned { kOpaque = 0, kSkinsView = 1, kSkinsLight = 2 };
constexpr unsigned kScenes = 3;
constexpr float kFar = std::numeric_limits<float>::infinity();

// What a frame's tracer builds, kept for the next frame to build into again (the Renderer
// keeps one set): a padded copy of the positions (where the mesh's own cannot be shared),
// the triangle normals, each scene's triangles and quads, and the Embree scenes. A frame
// loop then neither faults in nor unmaps these buffers every frame. Their contents are
// rebuilt from scratch each frame.
struct TracerBuffers {
  explicit TracerBuffers(RTCDevice device)
      : scenes{EmbreeScene(device), EmbreeScene(device), EmbreeScene(device)} {}
  MeshArray<float> vertices;
  MeshArray<Vec3> tri_normal;
  std::array<std::vector<std::uint32_t>, kScenes> tris;
  std::array<std::vector<TracedQuad>, kScenes> quads;  // primitives of each scene (SceneId)
  std::array<EmbreeScene, kScenes> scenes;
};

// Everything a tile needs to trace one frame; read-only while tracing.
class FrameTracer {
 public:
  FrameTracer(RTCDevice device, const SurfaceMesh& mesh, const Look& look, const Texture& texture,
              const PixelSampler& sampler, TracerBuffers& buffers)
      : mesh_(mesh), look_(look), texture_(texture), vertices_(buffers.vertices), tri_normal_(buffers.tri_normal),
        tris_(buffers.tris), quads_(buffers.quads), scenes_(buffers.scenes) {
    build(device, sampler.eye());
    // Primary rays of pixels whose rays cannot meet a scene's bounding box are left out of
    // its query, and a query with none left is not made (the background around the sheet;
    // for the skins, most packets): the same hits without Embree's cost per call.
    for (SceneId g : {kOpaque, kSkinsView})
      if (!quads_[g].empty()) {
        RTCBounds b;
        rtcGetSceneBounds(scenes_[g].scene, &b);
        pixels_[g] = sampler.covering({b.lower_x - eps_, b.lower_y - eps_, b.lower_z - eps_},
                                      {b.upper_x + eps_, b.upper_y + eps_, b.upper_z + eps_});
      }
  }

  // A surface point's shading up to the shadow ray: colour = albedo * (intensity *
  // weight * visibility + sky), with visibility asked along `to_light` from `shadow_from`
  // when `weight` > 0.
  // Trivially constructible (prepare() value-initialises it), so that arrays of them cost
  // nothing to set up.
  struct Shading {
    Vec3 albedo, shadow_from, to_light;
    float weight, sky;
    std::uint32_t tri;
    bool printed;  // the albedo comes from the print
    float light(float intensity, float visible) const { return intensity * (weight * visible) + sky; }
  };

  static constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();
  // What the first pass keeps of a sample besides its colour, for choosing a pixel's extra
  // samples (Renderer::draw).
  // Trivially constructible: a frame's worth is allocated without being cleared.
  struct SampleInfo {
    Vec3 plain;          // the colour with the print left blank: shading, edges, shadows
    float lighting;      // when the sample sees print directly: colour = print x lighting
    std::uint32_t print_tri;  // that print triangle, or kNoTriangle
  };

  // The colours of up to kPacket primary rays from one origin: out[i] for rays.dir[i].
  // Rays go to Embree as packets: one finds every ray's nearest opaque surface, then a
  // round per peeled skin in front of it; the shadow rays of all surfaces seen go out
  // together afterwards. Which rays share a packet is fixed by the caller, so the result
  // does not depend on the thread count. With `info`, info[i] describes out[i] too.
  void trace_packet(const Vec3& origin, const PacketRays& rays, Vec3* out, SampleInfo* info = nullptr) const {
    Packet nearest;  // lanes left out miss (geomID invalid, tfar = kFar)
    for (int i = 0; i < rays.count; ++i)
      if (pixels_[kOpaque].contains(rays.x[std::size_t(i)], rays.y[std::size_t(i)]))
        nearest.add(i, origin, rays.dir[std::size_t(i)], 0.0f, kFar);
    if (nearest.any) nearest.intersect(scenes_[kOpaque].scene, kQueryFlags);
    SkinHits skins;  // in front of each ray's opaque surface
    Packet skin;
    for (int i = 0; i < rays.count; ++i)
      if (pixels_[kSkinsView].contains(rays.x[std::size_t(i)], rays.y[std::size_t(i)]))
        skin.add(i, origin, rays.dir[std::size_t(i)], 0.0f, nearest.valid[i] != 0 ? nearest.rh.ray.tfar[i] : kFar);
    if (skin.any) skin.occluded(scenes_[kSkinsView].scene, skins.ctx);
    Surfaces seen;
    for (int i = 0; i < rays.count; ++i) {
      out[i] = Vec3::Zero();
      if (info) info[i] = SampleInfo{Vec3::Zero(), 0.0f, kNoTriangle};
      follow(origin, rays, i, nearest, skins, seen, [&](const Vec3& background) {
        out[i] += background;
        if (info) info[i].plain += background;
      });
    }
    std::array<float, kMaxSurfaces> visible;
    visibility(seen, visible);
    // Per ray, its surfaces in the order they were met.
    for (int k = 0; k < seen.count; ++k) {
      const Surface& f = seen.at[std::size_t(k)];
      const float light = f.shading.light(look_.intensity, visible[std::size_t(k)]);
      out[f.lane] += f.share * (f.shading.albedo * light);
      if (info) record(f.shading, f.share, light, info[f.lane]);
    }
  }

  // The print where a ray meets the plane of print triangle `tri` (continued beyond its
  // edges): a pixel's extra samples where only the print varies across it need no rays.
  Vec3 print_along(std::uint32_t tri, const Vec3& origin, const Vec3& dir) const {
    const auto& t = mesh_.triangles[tri];
    const Vec3 a = vec(mesh_.position[t[0]]), e1 = vec(mesh_.position[t[1]]) - a, e2 = vec(mesh_.position[t[2]]) - a;
    const Vec3 n = e1.cross(e2);
    const float facing = n.dot(dir), area2 = n.squaredNorm();
    if (!(std::abs(facing) > 1e-6f * std::sqrt(area2))) return albedo(tri, 1.0f / 3.0f, 1.0f / 3.0f);
    const Vec3 ap = origin + (n.dot(a - origin) / facing) * dir - a;
    return albedo(tri, ap.cross(e2).dot(n) / area2, e1.cross(ap).dot(n) / area2);
  }

 private:
  // A surface a primary ray meets, with the share of its pixel it gets.
  struct Surface {
    Shading shading;
    float share;
    int lane;
  };
  static constexpr int kMaxSurfaces = kPacket * kMaxLayersCrossed;
  struct Surfaces {
    std::array<Surface, kMaxSurfaces> at;
    int count = 0;
    void add(const Surface& f) { at[std::size_t(count++)] = f; }
  };

  // Adds a shaded surface to a sample's info. A share of 1 is an opaque surface with
  // nothing in front of it.
  void record(const Shading& seen, float share, float light, SampleInfo& info) const {
    info.plain += share * ((seen.printed ? look_.paper : seen.albedo) * light);
    if (seen.printed && share == 1.0f) {
      info.print_tri = seen.tri;
      info.lighting = light;
    }
  }

  // Every query is made as "coherent": for the shadow and skin queries too, whose rays start
  // at different points, this measured 20-30 % faster than Embree's default (incoherent)
  // on a torn frame, with the same hits (any-hit answers and gathered skins do not depend
  // on the order of traversal).
  static constexpr RTCIntersectContextFlags kQueryFlags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;

  // One Embree packet of rays: lane i is in use when valid[i].
  struct Packet {
    alignas(64) int valid[kPacket] = {};
    alignas(64) RTCRayHit16 rh;
    bool any = false;

    Packet() {
      for (int i = 0; i < kPacket; ++i) {
        set_lane(rh.ray, i, Vec3::Zero(), Vec3(0, 0, 1), 0.0f, kFar);
        rh.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID;
      }
    }
    void add(int i, const Vec3& o, const Vec3& d, float tnear, float tfar) {
      valid[i] = -1;
      any = true;
      set_lane(rh.ray, i, o, d, tnear, tfar);
    }
    void intersect(RTCScene scene, RTCIntersectContextFlags flags) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = flags;
      rtcIntersect16(valid, scene, &ctx, &rh);
    }
    void occluded(RTCScene scene) {
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      ctx.flags = kQueryFlags;
      occluded(scene, ctx);
    }
    void occluded(RTCScene scene, RTCIntersectContext& ctx) { rtcOccluded16(valid, scene, &ctx, &rh.ray); }
  };

  // The skins each ray of a packet enters, gathered in one traversal by the skin scene's
  // occlusion filter (which records each hit and rejects it, so the traversal goes on):
  // per lane the nearest kMaxLayersCrossed, sorted by (t, triangle), whatever order Embree
  // finds them in.
  struct SkinHit {
    float t;
    std::uint32_t tri;
    float u, v;  // barycentrics on triangle tri
    bool operator<(const SkinHit& o) const { return t < o.t || (t == o.t && tri < o.tri); }
  };
  struct SkinHits {
    RTCIntersectContext ctx;  // first: Embree hands the filter a pointer to it
    std::array<std::array<SkinHit, kMaxLayersCrossed>, kPacket> hit;
    std::array<int, kPacket> count{};
    SkinHits() {
      rtcInitIntersectContext(&ctx);
      ctx.flags = kQueryFlags;
    }
    void add(int lane, const SkinHit& h) {
      auto& list = hit[std::size_t(lane)];
      int& n = count[std::size_t(lane)];
      int at = 0;
      while (at < n && list[std::size_t(at)] < h) ++at;
      if (at == kMaxLayersCrossed || (at < n && !(h < list[std::size_t(at)]))) return;  // too far, or seen
      n = std::min(n + 1, kMaxLayersCrossed);
      for (int k = n - 1; k > at; --k) list[std::size_t(k)] = list[std::size_t(k - 1)];
      list[std::size_t(at)] = h;
    }
  };

  // Adds the surfaces ray i of `rays` meets to `seen`, in order: the skins it enters (each
  // passing on 1 - opacity of what is behind it), then its opaque surface; or, when it
  // misses that, calls background(its share of the background colour). As the walk of
  // closest hits did: hits closer than eps_ behind the last are the same surface again, a
  // ray crosses at most kMaxLayersCrossed surfaces and stops when less than 1/1024 is left.
  template <class Background>
  void follow(const Vec3& origin, const PacketRays& rays, int i, const Packet& nearest, const SkinHits& skins,
              Surfaces& seen, const Background& background) const {
    const auto li = std::size_t(i);
    const Vec3& dir = rays.dir[li];
    float throughput = 1.0f, next = 0.0f;
    int crossed = 0;
    for (int k = 0; k < skins.count[li]; ++k) {
      const SkinHit& h = skins.hit[li][std::size_t(k)];
      if (h.t < next) continue;
      if (crossed == kMaxLayersCrossed) return;
      const float alpha = mesh_.opacity[h.tri];
      seen.add({prepare(h.tri, h.u, h.v, h.t, origin, dir, rays.key[li]), throughput * alpha, i});
      ++crossed;
      throughput *= 1.0f - alpha;
      if (throughput < 1.0f / 1024.0f) return;
      next = h.t + eps_;
    }
    if (crossed == kMaxLayersCrossed) return;
    // A lane left out of the query misses: Embree may write hit fields of inactive lanes
    // (seen as a phantom line of paper along the culled rectangle's edge), so they are not read.
    if (nearest.valid[i] == 0 || nearest.rh.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID) {
      background(throughput * look_.background);
      return;
    }
    const TrianglePoint hit = on_triangle(quads_[kOpaque][nearest.rh.hit.primID[i]], nearest.rh.hit.u[i], nearest.rh.hit.v[i]);
    seen.add({prepare(hit.triangle, hit.u, hit.v, nearest.rh.ray.tfar[i], origin, dir, rays.key[li]), throughput, i});
  }

  // visible[k]: how much of the light reaches surface k: 0 behind anything opaque, reduced
  // by every peeled skin the shadow ray passes into. The shadow rays go out 16 at a time in
  // the surfaces' order, so packets are full even where few rays of a round have one.
  void visibility(const Surfaces& seen, std::array<float, kMaxSurfaces>& visible) const {
    Packet p;
    std::array<int, kPacket> surface{};
    int n = 0;
    for (int k = 0; k < seen.count; ++k) {
      const Shading& f = seen.at[std::size_t(k)].shading;
      visible[std::size_t(k)] = 1.0f;
      if (!(f.weight > 0.0f)) continue;
      surface[std::size_t(n)] = k;
      p.add(n, f.shadow_from, f.to_light, 0.0f, kFar);
      if (++n == kPacket) {
        shadow_packet(p, surface, seen, visible);
        p = Packet();
        n = 0;
      }
    }
    if (n > 0) shadow_packet(p, surface, seen, visible);
  }

  // Lane i of p is the shadow ray of surface `surface[i]`.
  void shadow_packet(Packet& p, const std::array<int, kPacket>& surface, const Surfaces& seen,
                     std::array<float, kMaxSurfaces>& visible) const {
    p.occluded(scenes_[kOpaque].scene);
    Packet skin;
    for (int i = 0; i < kPacket; ++i) {
      if (!p.valid[i]) continue;
      if (p.rh.ray.tfar[i] < 0.0f)
        visible[std::size_t(surface[std::size_t(i)])] = 0.0f;
      else if (!quads_[kSkinsLight].empty())
        skin.add(i, seen.at[std::size_t(surface[std::size_t(i)])].shading.shadow_from,
                 seen.at[std::size_t(surface[std::size_t(i)])].shading.to_light, 0.0f, kFar);
    }
    if (!skin.any) return;
    SkinHits hits;
    skin.occluded(scenes_[kSkinsLight].scene, hits.ctx);
    for (int i = 0; i < kPacket; ++i)
      if (skin.valid[i]) visible[std::size_t(surface[std::size_t(i)])] = through_skins(hits, i);
  }

  // The light let through by the skins a shadow ray enters, nearest first: each dims it by
  // its opacity, hits closer than eps_ behind the last one counted are the same surface
  // again, and after kMaxLayersCrossed skins or below 1/1024 it is dark.
  float through_skins(const SkinHits& hits, int lane) const {
    float v = 1.0f, next = 0.0f;
    for (int k = 0; k < hits.count[std::size_t(lane)]; ++k) {
      const SkinHit& h = hits.hit[std::size_t(lane)][std::size_t(k)];
      if (h.t < next) continue;
      v *= 1.0f - mesh_.opacity[h.tri];
      if (v < 1.0f / 1024.0f) return 0.0f;
      next = h.t + eps_;
    }
    return v;
  }

  static void set_lane(RTCRay16& r, int i, const Vec3& o, const Vec3& d, float tnear, float tfar) {
    r.org_x[i] = o.x(); r.org_y[i] = o.y(); r.org_z[i] = o.z();
    r.dir_x[i] = d.x(); r.dir_y[i] = d.y(); r.dir_z[i] = d.z();
    r.tnear[i] = tnear;
    r.tfar[i] = tfar;
    r.mask[i] = ~0u;
    r.time[i] = 0.0f;
    r.flags[i] = 0;
    r.id[i] = unsigned(i);  // the lane, for filters called on single rays
  }

  void build(RTCDevice device, const Vec3& eye) {
    sort_triangles(eye);
    share_vertices();
    for (unsigned g = 0; g < kScenes; ++g) {
      pair_triangles(mesh_, tris_[g], quads_[g]);
      attach(device, g);
      // Robust: no shortcuts that let rays slip between triangles sharing an edge.
      rtcSetSceneFlags(scenes_[g].scene, RTC_SCENE_FLAG_ROBUST);
      rtcSetSceneBuildQuality(scenes_[g].scene, RTC_BUILD_QUALITY_MEDIUM);
    }
    // The builds side by side: each is parallel inside, but the small skin scenes keep few
    // threads busy. A scene's BVH does not depend on how many threads build it.
    parallel_chunks(kScenes, 1, [&](std::size_t g, std::size_t, std::size_t) { rtcCommitScene(scenes_[g].scene); });
    check_device(device, "building the scene");
  }

  // Each triangle's unit normal; the triangles of each scene (SceneId), ascending. In
  // parallel over fixed chunks, the lists joined in chunk order.
  void sort_triangles(const Vec3& eye) {
    constexpr std::size_t kChunk = 16384;
    // Margins keep triangles seen (nearly) edge-on in both scenes. A shadow ray's direction
    // lies within `softness` of the light's centre, so n . d differs from n . to_light by
    // at most that.
    constexpr float kEdgeOn = 1e-3f;
    const float light_margin = look_.softness + kEdgeOn;
    const std::size_t nt = mesh_.triangle_count();
    tri_normal_.resize(nt);
    std::vector<std::array<std::vector<std::uint32_t>, kScenes>> parts(chunk_count(nt, kChunk));
    parallel_chunks(nt, kChunk, [&](std::size_t begin, std::size_t end, std::size_t c) {
      for (auto t = std::uint32_t(begin); t < end; ++t) {
        const auto& v = mesh_.triangles[t];
        const Vec3 a = vec(mesh_.position[v[0]]), b = vec(mesh_.position[v[1]]), d = vec(mesh_.position[v[2]]);
        const Vec3 n = (b - a).cross(d - a);
        const float len = n.norm();
        const bool flat = !(len > 0.0f);
        tri_normal_[t] = flat ? Vec3(0, 0, 1) : Vec3(n / len);
        const Vec3 from_eye = a - eye;
        // n . (a - eye) has one sign for all rays from the eye to the triangle's plane.
        const bool faces_eye = flat || tri_normal_[t].dot(from_eye) <= kEdgeOn * from_eye.norm();
        const float towards_light = tri_normal_[t].dot(look_.to_light);
        auto& part = parts[c];
        if (mesh_.opacity[t] < 1.0f) {
          // A shadow ray enters a skin where n . d < 0.
          if (faces_eye) part[kSkinsView].push_back(t);
          if (flat || towards_light <= light_margin) part[kSkinsLight].push_back(t);
        } else if (mesh_.material[t] != Material::Fibre || faces_eye || flat || towards_light >= -light_margin) {
          // A shadow ray leaves a fibre tooth (or a torn cell) through a side with n . d > 0.
          part[kOpaque].push_back(t);
        }
      }
    });
    for (unsigned g = 0; g < kScenes; ++g) {
      tris_[g].clear();
      for (const auto& part : parts) tris_[g].insert(tris_[g].end(), part[g].begin(), part[g].end());
    }
  }

  // The vertices both scenes read, and the ray offset off surfaces scaled to the mesh's
  // extent. Embree loads 16 bytes at a vertex, 4 past the last one's position: the mesh's own
  // array is shared when it has a spare element's room after its end (SurfaceMesh::resize
  // leaves one), else the positions are copied into a padded buffer.
  void share_vertices() {
    constexpr std::size_t kChunk = 65536;
    const std::size_t nv = mesh_.vertex_count();
    const bool spare = mesh_.position.capacity() > nv;
    if (!spare) {
      vertices_.resize(3 * nv + 4);
      std::fill(vertices_.end() - 4, vertices_.end(), 0.0f);
    }
    vertex_data_ = spare ? mesh_.position.data()->data() : vertices_.data();
    std::vector<float> extent(chunk_count(nv, kChunk), 0.0f);
    parallel_chunks(nv, kChunk, [&](std::size_t begin, std::size_t end, std::size_t c) {
      float e = 0.0f;
      for (std::size_t i = begin; i < end; ++i)
        for (std::size_t k = 0; k < 3; ++k) {
          if (!spare) vertices_[3 * i + k] = mesh_.position[i][k];
          e = std::max(e, std::abs(mesh_.position[i][k]));
        }
      extent[c] = e;
    });
    eps_ = 1e-4f;
    for (float e : extent) eps_ = std::max(eps_, 2e-5f * e);
  }

  // Puts the quads quads_[g] into scene g; its primitive p is quads_[g][p]. Embree reads
  // the vertices and the quads' corners where they are (shared buffers, no copies).
  void attach(RTCDevice device, unsigned g) {
    const std::vector<TracedQuad>& quads = quads_[g];
    if (quads.empty()) {
      scenes_[g].drop_geometry();
      return;
    }
    RTCGeometry geom = scenes_[g].use_geometry(device, RTC_GEOMETRY_TYPE_QUAD);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertex_data_, 0,
                               3 * sizeof(float), mesh_.vertex_count());
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT4, quads.data(),
                               offsetof(TracedQuad, vertex), sizeof(TracedQuad), quads.size());
    if (g != kOpaque) {
      geometry_[g] = {this, &quads_[g]};
      rtcSetGeometryUserData(geom, &geometry_[g]);
      rtcSetGeometryOccludedFilterFunction(geom, &FrameTracer::gather_entering);
    }
    rtcCommitGeometry(geom);
    check_device(device, "setting up geometry");
  }

  // The point of the mesh of lane i's candidate hit in a filter of the skin scene, and
  // whether the ray enters its triangle.
  static TrianglePoint hit_point(const RTCFilterFunctionNArguments* args, unsigned i) {
    const auto* geometry = static_cast<const GeometryData*>(args->geometryUserPtr);
    return on_triangle((*geometry->quads)[RTCHitN_primID(args->hit, args->N, i)], RTCHitN_u(args->hit, args->N, i),
                       RTCHitN_v(args->hit, args->N, i));
  }
  static bool hit_entering(const RTCFilterFunctionNArguments* args, unsigned i, std::uint32_t tri) {
    const auto* self = static_cast<const GeometryData*>(args->geometryUserPtr)->tracer;
    const Vec3 dir(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                   RTCRayN_dir_z(args->ray, args->N, i));
    return self->entering(tri, dir);
  }
  bool entering(std::uint32_t tri, const Vec3& dir) const { return tri_normal_[tri].dot(dir) < 0.0f; }

  // Occlusion filter of the skin scene: records the skins a ray enters in the query's
  // SkinHits and rejects every hit, so that the traversal finds them all. A ray leaving a
  // skin (seeing its back) neither sees it nor is dimmed by it: such hits are left out.
  static void gather_entering(const RTCFilterFunctionNArguments* args) {
    auto* hits = reinterpret_cast<SkinHits*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
      if (args->valid[i] == 0) continue;
      const TrianglePoint p = hit_point(args, i);
      if (hit_entering(args, i, p.triangle))
        hits->add(int(RTCRayN_id(args->ray, args->N, i)), {RTCRayN_tfar(args->ray, args->N, i), p.triangle, p.u, p.v});
      args->valid[i] = 0;
    }
  }

  Vec3 albedo(std::uint32_t tri, float u, float v) const {
    const float shade = mesh_.shade[tri];
    switch (mesh_.material[tri]) {
      case Material::Print: {
        if (!look_.print_enabled) return look_.paper;
        const auto& t = mesh_.triangles[tri];
        const float w = 1.0f - u - v;
        const float s = w * mesh_.uv[t[0]][0] + u * mesh_.uv[t[1]][0] + v * mesh_.uv[t[2]][0];
        const float r = w * mesh_.uv[t[0]][1] + u * mesh_.uv[t[1]][1] + v * mesh_.uv[t[2]][1];
        return texture_.sample(s, r);
      }
      case Material::Fibre: return look_.paper * (0.97f * shade);
      case Material::Paper: break;
    }
    return look_.paper * shade;
  }

  Vec3 shading_normal(std::uint32_t tri, float u, float v, const Vec3& geometric) const {
    const auto& t = mesh_.triangles[tri];
    const Vec3 n = (1.0f - u - v) * vec(mesh_.normal[t[0]]) + u * vec(mesh_.normal[t[1]]) + v * vec(mesh_.normal[t[2]]);
    const float len = n.norm();
    if (!(len > 0.0f) || n.dot(geometric) <= 0.0f) return geometric;
    return n / len;
  }

  // A point on the light's disc, hashed from the sample's key.
  Vec3 light_direction(std::uint64_t key) const {
    if (look_.softness <= 0.0f) return look_.to_light;
    HashStream rng(key ^ 0x6c69676874ull);
    const float r = look_.softness * std::sqrt(rng.uniform());
    const float phi = 6.2831853f * rng.uniform();
    return (look_.to_light + r * (std::cos(phi) * look_.light_u + std::sin(phi) * look_.light_v)).normalized();
  }

  Shading prepare(std::uint32_t tri, float u, float v, float t, const Vec3& origin, const Vec3& dir,
                  std::uint64_t key) const {
    const Vec3 point = origin + t * dir;
    Vec3 ng = tri_normal_[tri];
    Vec3 n = shading_normal(tri, u, v, ng);
    if (ng.dot(dir) > 0.0f) {  // seen from behind: light the side we see
      ng = -ng;
      n = -n;
    }
    Shading s{};
    // Shadow rays aim at a random point of the light's disc, which makes the penumbrae;
    // the cosine term takes the disc's centre: over a disc this small it varies by less
    // than its own noise would add, and a noise-free shading lets adaptive sampling find
    // edges rather than noise (Renderer::draw).
    s.to_light = light_direction(key);
    const float facing = n.dot(look_.to_light);
    const float alpha = mesh_.opacity[tri];
    // Loose fibres scatter light round themselves: "wrapped" diffuse and a fuller share of
    // the sky keep a torn edge paper-white instead of grey.
    const bool fibre = mesh_.material[tri] == Material::Fibre;
    const float lit = fibre ? (facing + kFibreWrap) / (1.0f + kFibreWrap) : facing;
    if (lit > 0.0f && (fibre || ng.dot(look_.to_light) > 0.0f)) {
      s.weight = lit;
      s.shadow_from = point + eps_ * ng;
    } else if (alpha < 1.0f && facing < 0.0f) {  // light through a thin skin from behind
      s.weight = -facing * 0.8f * (1.0f - alpha);
      s.shadow_from = point - eps_ * ng;
    }
    s.sky = look_.ambient * (fibre ? 0.85f : 0.55f + 0.45f * std::max(0.0f, n.z()));
    s.albedo = albedo(tri, u, v);
    s.tri = tri;
    s.printed = look_.print_enabled && mesh_.material[tri] == Material::Print;
    return s;
  }

  const SurfaceMesh& mesh_;
  const Look& look_;
  const Texture& texture_;
  // In the TracerBuffers the tracer was given.
  MeshArray<float>& vertices_;  // a padded copy of the positions, where needed (share_vertices)
  const float* vertex_data_ = nullptr;  // what Embree reads
  MeshArray<Vec3>& tri_normal_;
  std::array<std::vector<std::uint32_t>, kScenes>& tris_;  // the triangles of each scene (SceneId)
  std::array<std::vector<TracedQuad>, kScenes>& quads_;    // primitives of each scene
  // What a skin scene's filter is handed: the tracer and that scene's primitives.
  struct GeometryData {
    const FrameTracer* tracer;
    const std::vector<TracedQuad>* quads;
  };
  std::array<GeometryData, kScenes> geometry_{};
  std::array<EmbreeScene, kScenes>& scenes_;
  // Per scene for primary rays (kOpaque, kSkinsView): the pixels whose rays may meet it.
  std::array<PixelRect, kScenes> pixels_{};
  float eps_ = 1e-4f;
};

std::size_t tile_count(int width, int height) {
  return std::size_t((width + kTile - 1) / kTile) * std::size_t((height + kTile - 1) / kTile);
}

// Calls tile(x0, y0, x1, y1) for every tile, in parallel.
template <class Tile>
void for_each_tile(int width, int height, const Tile& tile) {
  const int tiles_x = (width + kTile - 1) / kTile;
  parallel_chunks(tile_count(width, height), 1, [&](std::size_t t, std::size_t, std::size_t) {
    const int x0 = int(t % std::size_t(tiles_x)) * kTile, y0 = int(t / std::size_t(tiles_x)) * kTile;
    tile(x0, y0, std::min(x0 + kTile, width), std::min(y0 + kTile, height));
  });
}

// Calls pixel(x, y) for the pixels of a tile, 4 x 4 blocks in turn: consecutive pixels are
// close together, so the rays of a packet stay coherent.
constexpr int kBlock = 4;
static_assert(kBlock * kBlock == kPacket && kTile % kBlock == 0);
template <class Pixel>
void for_each_pixel_by_block(int x0, int y0, int x1, int y1, const Pixel& pixel) {
  for (int by = y0; by < y1; by += kBlock)
    for (int bx = x0; bx < x1; bx += kBlock)
      for (int y = by; y < std::min(by + kBlock, y1); ++y)
        for (int x = bx; x < std::min(bx + kBlock, x1); ++x) pixel(x, y);
}

constexpr float kContrast = 0.015f;  // in linear light, about 1.5 % of white

// Whether a pixel's value differs visibly from one of its four neighbours'; value(i) is
// pixel i's.
template <class Value>
bool differs_from_neighbours(int width, int height, int x, int y, const Value& value) {
  const auto at = [&](int px, int py) -> const Vec3& { return value(std::size_t(py) * std::size_t(width) + std::size_t(px)); };
  const Vec3& c = at(x, y);
  const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  for (int n = 0; n < 4; ++n) {
    const int nx = x + dx[n], ny = y + dy[n];
    if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
    if ((at(nx, ny) - c).cwiseAbs().maxCoeff() > kContrast) return true;
  }
  return false;
}

// differs_from_neighbours() for every pixel of a tile at once, out[(y - y0) * kTile + x - x0],
// with the same result. A row of the tile is one run of floats, and its left, right, upper
// and lower neighbours are runs at fixed offsets, so the differences are taken channel by
// channel in loops without branches or gathers that the compiler vectorises; the pixels in
// the image's first and last columns, whose left or right neighbour is not in the image, are
// then tested one by one. Every pixel of a frame is tested: per pixel, with early exits, the
// test and its bookkeeping took about a tenth of pass 2's time on a torn frame.
void tile_contrast(const Vec3* value, int width, int height, int x0, int y0, int x1, int y1,
                   std::array<std::uint8_t, kTile * kTile>& out) {
  const auto row_step = std::ptrdiff_t(3) * width;
  // The run: pixels with both a left and a right neighbour in the image.
  const int xs = std::max(x0, 1), xe = std::min(x1, width - 1);
  const auto n = std::size_t(3 * std::max(xe - xs, 0));
  alignas(64) std::array<float, 3 * kTile> diff;
  const auto value_at = [&](std::size_t i) -> const Vec3& { return value[i]; };
  for (int y = y0; y < y1; ++y) {
    const float* c = value[std::size_t(y) * std::size_t(width) + std::size_t(xs)].data();
    // An upper or lower neighbour outside the image is the pixel itself (difference 0).
    const std::ptrdiff_t up = y > 0 ? -row_step : 0, down = y + 1 < height ? row_step : 0;
    for (std::size_t e = 0; e < n; ++e) {
      const auto i = std::ptrdiff_t(e);
      const float here = c[i];
      diff[e] = std::max(std::max(std::abs(c[i - 3] - here), std::abs(c[i + 3] - here)),
                         std::max(std::abs(c[i + up] - here), std::abs(c[i + down] - here)));
    }
    std::uint8_t* row = out.data() + std::size_t(y - y0) * kTile;
    for (std::size_t x = 0; x < n / 3; ++x)
      row[std::size_t(xs - x0) + x] = std::max(std::max(diff[3 * x], diff[3 * x + 1]), diff[3 * x + 2]) > kContrast;
    for (int x = x0; x < x1; ++x)
      if (x < xs || x >= xe) row[x - x0] = differs_from_neighbours(width, height, x, y, value_at);
  }
}

// One sample per pixel (adaptive sampling's first pass).
// Its arrays are not cleared when sized (every pixel is written): fresh pages are first
// touched by the threads tracing them, not by one thread beforehand.
struct FirstPass {
  void resize(std::size_t pixels) {
    colour.resize(pixels);
    info.resize(pixels);
  }
  MeshArray<Vec3> colour;
  MeshArray<FrameTracer::SampleInfo> info;
};

// Everything a frame allocates that is large, kept by the Renderer for the next frame.
struct FrameBuffers {
  explicit FrameBuffers(RTCDevice device) : tracer(device) {}
  SurfaceMesh mesh;  // draw(world, camera)'s
  TracerBuffers tracer;
  FirstPass first;
};

// What a pixel's remaining samples need. Where it differs from a neighbour in shading, at a
// silhouette, an edge or a shadow's boundary, they are traced; where only the print differs
// (most such pixels of a printed sheet), the print is looked up where the samples would
// meet the same flat surface, lit as the first sample. Flat areas are already converged.
enum class Refinement { none, rays, print };
// `contrast`: whether its colour differs from a neighbour's (tile_contrast).
Refinement refinement(const FirstPass& first, int width, int height, int x, int y, bool contrast) {
  if (!contrast) return Refinement::none;
  if (differs_from_neighbours(width, height, x, y, [&](std::size_t i) -> const Vec3& { return first.info[i].plain; }))
    return Refinement::rays;
  const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
  return first.info[i].print_tri != FrameTracer::kNoTriangle ? Refinement::print : Refinement::rays;
}

}  // namespace

struct Renderer::Impl {
  RenderSettings settings;
  Image print;
  Texture texture;
  SrgbEncoder encode;
  Look look{};
  RTCDevice device = nullptr;
  // The buffers kept from one draw() to the next. draw() is const and may be called from
  // several threads at once: a call that finds them in use works with buffers of its own.
  std::mutex buffers_in_use;
  std::unique_ptr<FrameBuffers> buffers;

  explicit Impl(const RenderSettings& s) : settings(checked(s)), print(load_print(s.print)), texture(print) {
    device = rtcNewDevice(nullptr);
    if (!device) throw RenderError("Embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    look.background = linear_colour(s.background);
    look.paper = linear_colour(s.paper_color);
    look.to_light = -Vec3(float(s.light.direction[0]), float(s.light.direction[1]), float(s.light.direction[2])).normalized();
    const Vec3 helper = std::abs(look.to_light.z()) < 0.9f ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
    look.light_u = look.to_light.cross(helper).normalized();
    look.light_v = look.to_light.cross(look.light_u);
    look.softness = float(s.light.softness);
    look.intensity = float(s.light.intensity);
    look.ambient = float(s.light.ambient);
    look.exposure = float(s.exposure);
    look.print_enabled = s.print.enabled;
  }
  ~Impl() {
    buffers.reset();  // its scenes before the device
    if (device) rtcReleaseDevice(device);
  }

  FrameBuffers& kept_buffers() {
    if (!buffers) buffers = std::make_unique<FrameBuffers>(device);
    return *buffers;
  }

  Image frame(const SurfaceMesh& mesh, const Camera& camera, FrameBuffers& kept) const;
};

Renderer::Renderer(const RenderSettings& settings) : impl_(std::make_unique<Impl>(settings)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

const RenderSettings& Renderer::settings() const { return impl_->settings; }
const Image& Renderer::print() const { return impl_->print; }

MeshOptions Renderer::mesh_options() const {
  return {impl_->settings.fray, float(impl_->settings.fray_length), float(impl_->settings.layer_opacity)};
}

Camera Renderer::camera_for(const World& world) const {
  return make_camera(impl_->settings.camera, rest_bounds(world), impl_->settings.width, impl_->settings.height);
}

Image Renderer::draw(const World& world, const Camera& camera) const {
  std::unique_lock lock(impl_->buffers_in_use, std::try_to_lock);
  if (!lock) {
    SurfaceMesh mesh = build_surface_mesh(world, mesh_options());
    append_indenter(world, mesh);
    return draw(mesh, camera);
  }
  FrameBuffers& buffers = impl_->kept_buffers();
  build_surface_mesh(world, mesh_options(), buffers.mesh);
  append_indenter(world, buffers.mesh);
  return impl_->frame(buffers.mesh, camera, buffers);
}

Image Renderer::draw(const SurfaceMesh& mesh, const Camera& camera) const {
  std::unique_lock lock(impl_->buffers_in_use, std::try_to_lock);
  if (lock) return impl_->frame(mesh, camera, impl_->kept_buffers());
  FrameBuffers own(impl_->device);
  return impl_->frame(mesh, camera, own);
}

Image Renderer::Impl::frame(const SurfaceMesh& mesh, const Camera& camera, FrameBuffers& kept) const {
  const RenderSettings& s = settings;
  const PixelSampler sampler(camera, s.width, s.height, s.samples);
  const FrameTracer tracer(device, mesh, look, texture, sampler, kept.tracer);
  const std::size_t pixels = std::size_t(s.width) * std::size_t(s.height);
  // Pass 1: one ray per pixel. Pass 2: the remaining samples where a pixel needs them
  // (refinement()). Both passes read only pass 1's results, so the choice is deterministic.
  // Rays go out in packets of consecutive samples in a tile's block order.
  FirstPass& first = kept.first;
  first.resize(pixels);
  const auto index = [&](int x, int y) { return std::size_t(y) * std::size_t(s.width) + std::size_t(x); };
  for_each_tile(s.width, s.height, [&](int x0, int y0, int x1, int y1) {
    PacketRays rays;
    std::array<std::size_t, kPacket> dest{};
    std::array<Vec3, kPacket> out;
    std::array<FrameTracer::SampleInfo, kPacket> info;
    auto flush = [&] {
      sampler.aim(rays);
      tracer.trace_packet(sampler.eye(), rays, out.data(), info.data());
      for (int i = 0; i < rays.count; ++i) {
        first.colour[dest[std::size_t(i)]] = out[std::size_t(i)];
        first.info[dest[std::size_t(i)]] = info[std::size_t(i)];
      }
      rays.count = 0;
    };
    for_each_pixel_by_block(x0, y0, x1, y1, [&](int x, int y) {
      dest[std::size_t(rays.count)] = index(x, y);
      sampler.add(rays, x, y, 0);
      if (rays.count == kPacket) flush();
    });
    if (rays.count > 0) flush();
  });
  Image image(s.width, s.height);
  const float exposure = look.exposure;
  const auto put = [&](std::size_t i, const Vec3& colour) {
    std::uint8_t* p = image.rgb.data() + 3 * i;
    for (int c = 0; c < 3; ++c) p[c] = encode(colour[c] * exposure);
  };
  for_each_tile(s.width, s.height, [&](int x0, int y0, int x1, int y1) {
    // The extra samples of this tile's pixels that need rays, k = 1, 2, ... per pixel, and
    // the pixels that need only the print.
    std::vector<std::size_t> pixel_of;
    std::vector<Vec3> sample;
    std::vector<std::array<int, 2>> print_only;
    std::vector<Vec3> print_sample;  // the print at each extra sample of print_only's pixels
    PacketRays rays;
    auto flush = [&] {
      sampler.aim(rays);
      sample.resize(sample.size() + std::size_t(rays.count));
      tracer.trace_packet(sampler.eye(), rays, sample.data() + sample.size() - std::size_t(rays.count));
      rays.count = 0;
    };
    std::array<std::uint8_t, kTile * kTile> contrast;
    if (s.samples > 1) tile_contrast(first.colour.data(), s.width, s.height, x0, y0, x1, y1, contrast);
    if (s.samples > 1)
      for_each_pixel_by_block(x0, y0, x1, y1, [&](int x, int y) {
        const bool differs = contrast[std::size_t(y - y0) * kTile + std::size_t(x - x0)] != 0;
        const Refinement r = refinement(first, s.width, s.height, x, y, differs);
        if (r == Refinement::print) print_only.push_back({x, y});
        if (r != Refinement::rays) return;
        for (int k = 1; k < s.samples; ++k) {
          pixel_of.push_back(index(x, y));
          sampler.add(rays, x, y, k);
          if (rays.count == kPacket) flush();
        }
      });
    if (rays.count > 0) flush();
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) put(index(x, y), first.colour[index(x, y)]);
    // Pixels with extra samples (overwritten): their mean, summed in sample order.
    for (std::size_t j = 0; j < pixel_of.size();) {
      const std::size_t i = pixel_of[j];
      Vec3 colour = first.colour[i];
      for (; j < pixel_of.size() && pixel_of[j] == i; ++j) colour += sample[j];
      put(i, colour / float(s.samples));
    }
    // Pixels that need only the print: their extra samples aimed 16 at a time (aim() is
    // vectorised; aiming one sample at a time was a third of this part), the print looked up
    // where each meets the pixel's print triangle, then each pixel's mean in sample order.
    PacketRays print_rays;
    std::array<std::uint32_t, kPacket> print_tri{};
    auto flush_print = [&] {
      sampler.aim(print_rays);
      for (int l = 0; l < print_rays.count; ++l)
        print_sample.push_back(tracer.print_along(print_tri[std::size_t(l)], sampler.eye(), print_rays.dir[std::size_t(l)]));
      print_rays.count = 0;
    };
    for (const auto& [x, y] : print_only)
      for (int k = 1; k < s.samples; ++k) {
        print_tri[std::size_t(print_rays.count)] = first.info[index(x, y)].print_tri;
        sampler.add(print_rays, x, y, k);
        if (print_rays.count == kPacket) flush_print();
      }
    if (print_rays.count > 0) flush_print();
    for (std::size_t p = 0, j = 0; p < print_only.size(); ++p) {
      const std::size_t i = index(print_only[p][0], print_only[p][1]);
      Vec3 colour = first.colour[i];
      for (int k = 1; k < s.samples; ++k) colour += first.info[i].lighting * print_sample[j++];
      put(i, colour / float(s.samples));
    }
  });
  return image;
}

}  // namespace papertear::render
