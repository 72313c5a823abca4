#include "tools/render/raytracer.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "kernels/parallel.hpp"
#include "tools/render/hash.hpp"
#include "tools/render/print.hpp"

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
    return lut_[std::size_t(std::lround(c * float(kSteps)))];
  }

 private:
  static constexpr int kSteps = 8192;
  std::array<std::uint8_t, kSteps + 1> lut_{};
};

struct EmbreeScene {
  RTCScene scene = nullptr;
  explicit EmbreeScene(RTCDevice device) : scene(rtcNewScene(device)) {}
  ~EmbreeScene() {
    if (scene) rtcReleaseScene(scene);
  }
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;
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

struct Renderer::Impl {
  RenderSettings settings;
  Image print;
  Texture texture;
  SrgbEncoder encode;
  Look look{};
  RTCDevice device = nullptr;

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
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

// Ray masks: opaque triangles and peeled skins are two geometries of one scene, so a
// shadow ray can skip the skins without a second BVH.
constexpr unsigned kOpaqueMask = 1u, kSkinMask = 2u, kAnyMask = kOpaqueMask | kSkinMask;

// Everything a tile needs to trace one frame; read-only while tracing.
class FrameTracer {
 public:
  FrameTracer(RTCDevice device, const SurfaceMesh& mesh, const Look& look, const Texture& texture)
      : mesh_(mesh), look_(look), texture_(texture), scene_(device) {
    build(device);
  }

  Vec3 trace(const Vec3& origin, const Vec3& dir, std::uint64_t key) const {
    Vec3 colour = Vec3::Zero();
    float throughput = 1.0f;
    float tnear = 0.0f;
    for (int layer = 0; layer < kMaxLayersCrossed; ++layer) {
      RTCRayHit rh = make_ray(origin, dir, tnear, kAnyMask);
      RTCIntersectContext ctx;
      rtcInitIntersectContext(&ctx);
      rtcIntersect1(scene_.scene, &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return colour + throughput * look_.background;
      const std::uint32_t tri = triangle(rh.hit);
      const float alpha = mesh_.opacity[tri];
      const bool entering = tri_normal_[tri].dot(dir) < 0.0f;
      if (alpha >= 1.0f) return colour + throughput * shade(rh, tri, origin, dir, key);
      if (entering) {  // a peeled skin: its own colour, then what is behind it
        colour += throughput * alpha * shade(rh, tri, origin, dir, key);
        throughput *= 1.0f - alpha;
        if (throughput < 1.0f / 1024.0f) return colour;
      }
      tnear = rh.ray.tfar + eps_;
    }
    return colour;
  }

 private:
  void build(RTCDevice device) {
    const std::size_t nv = mesh_.vertex_count(), nt = mesh_.triangle_count();
    tri_normal_.resize(nt);
    for (std::uint32_t t = 0; t < nt; ++t) {
      const auto& v = mesh_.triangles[t];
      const Vec3 a = vec(mesh_.position[v[0]]), b = vec(mesh_.position[v[1]]), c = vec(mesh_.position[v[2]]);
      const Vec3 n = (b - a).cross(c - a);
      const float len = n.norm();
      tri_normal_[t] = len > 0.0f ? Vec3(n / len) : Vec3(0, 0, 1);
      (mesh_.opacity[t] < 1.0f ? ids_[1] : ids_[0]).push_back(t);
    }
    float extent = 0.0f;
    for (const auto& p : mesh_.position) extent = std::max({extent, std::abs(p[0]), std::abs(p[1]), std::abs(p[2])});
    eps_ = std::max(1e-4f, 2e-5f * extent);
    // One copy of the vertices for both geometries; Embree reads up to 16 bytes at a time,
    // hence the padding.
    vertices_.resize(3 * nv + 4, 0.0f);
    for (std::size_t i = 0; i < nv; ++i)
      for (std::size_t c = 0; c < 3; ++c) vertices_[3 * i + c] = mesh_.position[i][c];
    attach(device, 0, kOpaqueMask);
    attach(device, 1, kSkinMask);
    // Robust: no shortcuts that let rays slip between triangles sharing an edge.
    rtcSetSceneFlags(scene_.scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_.scene, RTC_BUILD_QUALITY_MEDIUM);
    rtcCommitScene(scene_.scene);
    check_device(device, "building the scene");
  }

  // Puts the triangles ids_[g] into the scene as geometry g; its primitive p is triangle
  // ids_[g][p].
  void attach(RTCDevice device, unsigned g, unsigned mask) {
    const std::vector<std::uint32_t>& tris = ids_[g];
    if (tris.empty()) return;
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices_.data(), 0,
                               3 * sizeof(float), mesh_.vertex_count());
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), tris.size()));
    check_device(device, "allocating geometry");
    for (std::size_t p = 0; p < tris.size(); ++p)
      for (std::size_t c = 0; c < 3; ++c) ib[3 * p + c] = mesh_.triangles[tris[p]][c];
    rtcSetGeometryMask(geom, mask);
    rtcCommitGeometry(geom);
    rtcAttachGeometryByID(scene_.scene, geom, g);
    rtcReleaseGeometry(geom);
  }

  std::uint32_t triangle(const RTCHit& hit) const { return ids_[hit.geomID][hit.primID]; }

  static RTCRayHit make_ray(const Vec3& o, const Vec3& d, float tnear, unsigned mask) {
    RTCRayHit rh{};
    rh.ray.org_x = o.x(); rh.ray.org_y = o.y(); rh.ray.org_z = o.z();
    rh.ray.dir_x = d.x(); rh.ray.dir_y = d.y(); rh.ray.dir_z = d.z();
    rh.ray.tnear = tnear;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = mask;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
  }

  // How much of the light reaches `origin` along `dir`: 0 behind anything opaque, reduced by
  // every peeled skin the shadow ray passes into. Without skins one any-hit query answers
  // it; with skins the hits are walked in order (one closest-hit query when nothing is in
  // the way, the common case, instead of an any-hit query plus a walk through the skins).
  float visibility(const Vec3& origin, const Vec3& dir) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    if (ids_[1].empty()) {
      RTCRay ray = make_ray(origin, dir, 0.0f, kOpaqueMask).ray;
      rtcOccluded1(scene_.scene, &ctx, &ray);
      return ray.tfar < 0.0f ? 0.0f : 1.0f;
    }
    float transmitted = 1.0f, tnear = 0.0f;
    for (int layer = 0; layer < kMaxLayersCrossed; ++layer) {
      RTCRayHit rh = make_ray(origin, dir, tnear, kAnyMask);
      rtcIntersect1(scene_.scene, &ctx, &rh);
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return transmitted;
      if (rh.hit.geomID == 0) return 0.0f;
      const std::uint32_t tri = triangle(rh.hit);
      if (tri_normal_[tri].dot(dir) < 0.0f) transmitted *= 1.0f - mesh_.opacity[tri];
      if (transmitted < 1.0f / 1024.0f) return 0.0f;
      tnear = rh.ray.tfar + eps_;
    }
    return transmitted;
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

  Vec3 shade(const RTCRayHit& rh, std::uint32_t tri, const Vec3& origin, const Vec3& dir, std::uint64_t key) const {
    const Vec3 point = origin + rh.ray.tfar * dir;
    Vec3 ng = tri_normal_[tri];
    Vec3 n = shading_normal(tri, rh.hit.u, rh.hit.v, ng);
    if (ng.dot(dir) > 0.0f) {  // seen from behind: light the side we see
      ng = -ng;
      n = -n;
    }
    const Vec3 to_light = light_direction(key);
    const float facing = n.dot(to_light);
    const float alpha = mesh_.opacity[tri];
    // Loose fibres scatter light round themselves: "wrapped" diffuse and a fuller share of
    // the sky keep a torn edge paper-white instead of grey.
    const bool fibre = mesh_.material[tri] == Material::Fibre;
    const float lit = fibre ? (facing + kFibreWrap) / (1.0f + kFibreWrap) : facing;
    float direct = 0.0f;
    if (lit > 0.0f && (fibre || ng.dot(to_light) > 0.0f)) {
      direct = lit * visibility(point + eps_ * ng, to_light);
    } else if (alpha < 1.0f && facing < 0.0f) {  // light through a thin skin from behind
      direct = -facing * 0.8f * (1.0f - alpha) * visibility(point - eps_ * ng, to_light);
    }
    const float sky = look_.ambient * (fibre ? 0.85f : 0.55f + 0.45f * std::max(0.0f, n.z()));
    return albedo(tri, rh.hit.u, rh.hit.v) * (look_.intensity * direct + sky);
  }

  const SurfaceMesh& mesh_;
  const Look& look_;
  const Texture& texture_;
  std::vector<float> vertices_;
  std::vector<Vec3> tri_normal_;
  std::array<std::vector<std::uint32_t>, 2> ids_;  // triangles of geometry 0 (opaque) and 1 (skins)
  EmbreeScene scene_;
  float eps_ = 1e-4f;
};

// Sub-pixel position of sample s: the R2 sequence (a low-discrepancy rank-1 lattice), shifted
// per pixel by a hashed offset so neighbouring pixels do not share a pattern.
std::array<float, 2> subpixel(int x, int y, int s, int samples) {
  if (samples == 1) return {0.5f, 0.5f};
  HashStream rng(hash_key(std::uint64_t(x), std::uint64_t(y), 0x7069786c));
  const float ox = rng.uniform(), oy = rng.uniform();
  const float gx = 0.7548776662f * float(s) + ox, gy = 0.5698402910f * float(s) + oy;
  return {gx - std::floor(gx), gy - std::floor(gy)};
}

// Primary rays of one frame.
class PixelSampler {
 public:
  PixelSampler(const Camera& c, int width, int height, int samples)
      : eye_(vec(c.position)), fwd_(vec(c.forward)), right_(vec(c.right)), up_(vec(c.up)),
        ty_(c.tan_half_fov_y), tx_(c.tan_half_fov_y * c.aspect), width_(width), height_(height), samples_(samples) {}

  Vec3 trace(const FrameTracer& tracer, int x, int y, int k) const {
    const auto off = subpixel(x, y, k, samples_);
    const float ndc_x = (2.0f * (float(x) + off[0]) / float(width_) - 1.0f) * tx_;
    const float ndc_y = (1.0f - 2.0f * (float(y) + off[1]) / float(height_)) * ty_;
    const Vec3 dir = (fwd_ + ndc_x * right_ + ndc_y * up_).normalized();
    return tracer.trace(eye_, dir, hash_key(std::uint64_t(x), std::uint64_t(y), std::uint64_t(k)));
  }

 private:
  Vec3 eye_, fwd_, right_, up_;
  float ty_, tx_;
  int width_, height_, samples_;
};

std::size_t tile_count(int width, int height) {
  return std::size_t((width + kTile - 1) / kTile) * std::size_t((height + kTile - 1) / kTile);
}

// Calls pixel(x, y) for every pixel, tiles in parallel (each pixel exactly once).
template <class Pixel>
void for_each_tile(int width, int height, const Pixel& pixel) {
  const int tiles_x = (width + kTile - 1) / kTile;
  parallel_chunks(tile_count(width, height), 1, [&](std::size_t tile, std::size_t, std::size_t) {
    const int x0 = int(tile % std::size_t(tiles_x)) * kTile, y0 = int(tile / std::size_t(tiles_x)) * kTile;
    for (int y = y0; y < std::min(y0 + kTile, height); ++y)
      for (int x = x0; x < std::min(x0 + kTile, width); ++x) pixel(x, y);
  });
}

// Whether a pixel's first sample differs visibly from one of its four neighbours'.
bool differs_from_neighbours(const std::vector<Vec3>& first, int width, int height, int x, int y) {
  constexpr float kContrast = 0.015f;  // in linear light, about 1.5 % of white
  const Vec3& c = first[std::size_t(y) * std::size_t(width) + std::size_t(x)];
  const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
  for (int n = 0; n < 4; ++n) {
    const int nx = x + dx[n], ny = y + dy[n];
    if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
    const Vec3 d = first[std::size_t(ny) * std::size_t(width) + std::size_t(nx)] - c;
    if (d.cwiseAbs().maxCoeff() > kContrast) return true;
  }
  return false;
}

}  // namespace

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
  return draw(build_surface_mesh(world, mesh_options()), camera);
}

Image Renderer::draw(const SurfaceMesh& mesh, const Camera& camera) const {
  const RenderSettings& s = impl_->settings;
  const FrameTracer tracer(impl_->device, mesh, impl_->look, impl_->texture);
  const PixelSampler sampler(camera, s.width, s.height, s.samples);
  const std::size_t pixels = std::size_t(s.width) * std::size_t(s.height);
  // Pass 1: one ray per pixel. Pass 2: the remaining samples, only where a pixel differs
  // from a neighbour (edges, print detail, shadow boundaries); flat areas are already
  // converged. Both passes read only pass 1's results, so the choice is deterministic.
  std::vector<Vec3> first(pixels);
  for_each_tile(s.width, s.height, [&](int x, int y) {
    first[std::size_t(y) * std::size_t(s.width) + std::size_t(x)] = sampler.trace(tracer, x, y, 0);
  });
  Image image(s.width, s.height);
  const float exposure = impl_->look.exposure;
  const SrgbEncoder& encode = impl_->encode;
  for_each_tile(s.width, s.height, [&](int x, int y) {
    const std::size_t i = std::size_t(y) * std::size_t(s.width) + std::size_t(x);
    Vec3 colour = first[i];
    if (s.samples > 1 && differs_from_neighbours(first, s.width, s.height, x, y)) {
      for (int k = 1; k < s.samples; ++k) colour += sampler.trace(tracer, x, y, k);
      colour /= float(s.samples);
    }
    std::uint8_t* p = image.pixel(x, y);
    for (int c = 0; c < 3; ++c) p[c] = encode(colour[c] * exposure);
  });
  return image;
}

}  // namespace papertear::render
