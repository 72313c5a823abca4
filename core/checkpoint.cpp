#include "core/checkpoint.hpp"

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <type_traits>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/invariants.hpp"
#include "core/lattice_builder.hpp"

namespace papertear {
namespace {

using Kind = CheckpointError::Kind;

// Thrown without a prefix; the public entry points add "checkpoint: " or the file's path.
[[noreturn]] void fail(Kind kind, const std::string& detail) {
  throw CheckpointError(kind, std::string(checkpoint_error_name(kind)) + ": " + detail);
}

[[noreturn]] void inconsistent(const std::string& detail) { fail(Kind::Inconsistent, detail); }

std::string str(std::uint64_t v) { return std::to_string(v); }

// ---------------------------------------------------------------------------------------
// Little-endian encoding. On a little-endian host a column is one memcpy; elsewhere each
// value is written byte by byte, so the file is the same on every host.

template <class T>
using Bits = std::conditional_t<sizeof(T) == 1, std::uint8_t,
             std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>;

template <class T>
void put_le(std::string& out, T value) {
  static_assert(std::is_trivially_copyable_v<T> && (sizeof(T) == 1 || sizeof(T) == 4 || sizeof(T) == 8));
  const auto bits = std::bit_cast<Bits<T>>(value);
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(char((bits >> (8 * i)) & 0xffu));
}

template <class T>
T get_le(const char* p) {
  Bits<T> bits = 0;
  for (std::size_t i = 0; i < sizeof(T); ++i)
    bits = Bits<T>(bits | Bits<T>(Bits<T>(static_cast<unsigned char>(p[i])) << (8 * i)));
  return std::bit_cast<T>(bits);
}

class ByteWriter {
 public:
  void tag(std::string_view t) { out_.append(t); }
  template <class T>
  void value(T v) { put_le(out_, v); }
  void flag(bool b) { value(std::uint8_t(b ? 1 : 0)); }
  void letter(char c) { value(static_cast<std::uint8_t>(c)); }
  void text(std::string_view s) {
    value(std::uint64_t(s.size()));
    out_.append(s);
  }
  template <class T>
  void column(const T* data, std::size_t n) {
    value(std::uint64_t(n));
    if constexpr (std::endian::native == std::endian::little) {
      out_.append(reinterpret_cast<const char*>(data), n * sizeof(T));
    } else {
      for (std::size_t i = 0; i < n; ++i) put_le(out_, data[i]);
    }
  }
  template <class C>
  void column(const C& c) { column(c.data(), c.size()); }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class ByteReader {
 public:
  explicit ByteReader(std::string_view bytes) : all_(bytes), rest_(bytes) {}

  void section(std::string_view t) {
    section_ = std::string(t);
    const std::string_view got = take(t.size(), "the section tag");
    if (got != t)
      inconsistent("expected section " + section_ + " at payload offset " + str(offset() - t.size()));
  }
  template <class T>
  T value(const char* what) { return get_le<T>(take(sizeof(T), what).data()); }
  bool flag(const char* what) {
    const auto b = value<std::uint8_t>(what);
    if (b > 1) inconsistent(std::string(what) + " in section " + section_ + " is " + str(b) + ", not 0 or 1");
    return b == 1;
  }
  char letter(const char* what) { return static_cast<char>(value<std::uint8_t>(what)); }
  std::string text(const char* what) {
    const std::uint64_t n = count(1, what);
    return std::string(take(std::size_t(n), what));
  }
  // A column's element count, refused before anything is allocated when the elements
  // cannot fit in what is left of the payload.
  std::uint64_t count(std::size_t element_size, const char* what) {
    const auto n = value<std::uint64_t>(what);
    if (n > rest_.size() / element_size)
      fail(Kind::Truncated, std::string(what) + " in section " + section_ + " claims " + str(n) +
                                " elements of " + str(element_size) + " bytes, but only " + str(rest_.size()) +
                                " bytes of the payload remain");
    return n;
  }
  template <class C>
  void column(C& out, const char* what) {
    using T = std::remove_cvref_t<decltype(out[0])>;
    const auto n = std::size_t(count(sizeof(T), what));
    out.resize(n);
    const char* p = take(n * sizeof(T), what).data();
    if constexpr (std::endian::native == std::endian::little) {
      if (n) std::memcpy(static_cast<void*>(out.data()), p, n * sizeof(T));
    } else {
      for (std::size_t i = 0; i < n; ++i) out[i] = get_le<T>(p + i * sizeof(T));
    }
  }
  template <class T, std::size_t N>
  void fixed(std::array<T, N>& out, const char* what) {
    for (T& v : out) v = value<T>(what);
  }
  std::size_t offset() const { return all_.size() - rest_.size(); }
  std::size_t remaining() const { return rest_.size(); }

 private:
  std::string_view take(std::size_t n, const char* what) {
    if (n > rest_.size())
      fail(Kind::Truncated, "reading " + std::string(what) + " in section " + section_ + " needs " + str(n) +
                                " bytes at payload offset " + str(offset()) + ", only " + str(rest_.size()) +
                                " remain");
    std::string_view out = rest_.substr(0, n);
    rest_.remove_prefix(n);
    return out;
  }

  std::string_view all_, rest_;
  std::string section_ = "(none)";
};

// ---------------------------------------------------------------------------------------
// Writing. Every field is named explicitly: a field added to a struct must be added here,
// to the reader below, and the format version bumped.

void write_scene(ByteWriter& w, const Scene& s) {
  w.tag("SCEN");
  for (int v : s.sheet.cells) w.value(std::int32_t(v));
  for (double v : s.sheet.cell_size) w.value(v);
  w.value(s.sheet.density);

  const MaterialParams& m = s.material;
  w.text(m.preset);
  w.letter(m.grain);
  for (double v : {m.k_edge, m.k_face, m.k_body, m.damping, m.grain_stiffness, m.fiber_length,
                   m.fiber_length_sigma})
    w.value(v);
  w.value(std::int32_t(m.block_width));
  w.value(std::int32_t(m.block_depth));
  for (double v : {m.block_stiffness, m.strain_intra, m.strain_inter, m.strain_layer, m.strain_surface,
                   m.grain_strength, m.strength_jitter})
    w.value(v);

  const LoadParams& l = s.load;
  w.text(l.kind);
  w.letter(l.axis);
  w.value(std::int32_t(l.grip_cells));
  w.value(l.speed);
  w.value(l.ramp_time);
  w.value(std::int32_t(l.grip_margin));
  w.value(std::int32_t(l.notch));
  w.text(l.indenter);
  for (double v : {l.indenter_radius, l.indenter_angle, l.indenter_at[0], l.indenter_at[1], l.contact_stiffness})
    w.value(v);

  for (double v : s.world.gravity) w.value(v);
  w.value(s.world.drag);

  const RunParams& r = s.run;
  w.value(std::int32_t(r.steps));
  w.value(r.dt);
  w.value(r.dt_safety);
  w.value(std::int32_t(r.frames));
  w.value(std::uint64_t(r.seed));
  w.value(std::int32_t(r.max_splits_per_step));

  w.value(std::uint64_t(s.lines.size()));
  for (const LineParams& line : s.lines) {
    w.text(line.kind);
    w.value(std::uint64_t(line.points.size()));
    for (const auto& p : line.points) {
      w.value(p[0]);
      w.value(p[1]);
    }
    w.value(line.strength);
    w.value(std::int32_t(line.depth));
    w.value(line.pitch);
    w.value(line.duty);
  }
}

void write_nodes(ByteWriter& w, const NodeStore& n) {
  w.tag("NODE");
  w.value(std::uint64_t(n.count));
  for (const AlignedArray<float>* c : {&n.px, &n.py, &n.pz, &n.vx, &n.vy, &n.vz, &n.inv_mass, &n.free_mask, &n.mass})
    w.column(*c);
  w.column(n.vertex);
  w.column(n.grip);
}

void write_topology(ByteWriter& w, const Topology& t) {
  w.tag("TOPO");
  w.value(std::int32_t(t.dims.nx));
  w.value(std::int32_t(t.dims.ny));
  w.value(std::int32_t(t.dims.nl));
  w.value(t.dims.hx);
  w.value(t.dims.hy);
  w.value(t.dims.hz);
  w.column(t.cell_nodes);
  for (const auto& list : t.colour_cells) w.column(list);
  w.column(t.cell_scale);
  w.column(t.cell_block);
  w.column(t.face_strain);
}

void write_springs(ByteWriter& w, const SpringTable& s) {
  w.tag("SPRG");
  for (const auto* a : {&s.rest, &s.stiffness, &s.damping})
    for (float v : *a) w.value(v);
}

void write_coarse(ByteWriter& w, const CoarseSprings& c) {
  w.tag("CRSE");
  w.column(c.cell_a);
  w.column(c.cell_b);
  w.column(c.corner_a);
  w.column(c.corner_b);
  w.column(c.rest);
  w.column(c.stiffness);
  w.column(c.damping);
  w.column(c.block);
}

void write_blocks(ByteWriter& w, const std::vector<Block>& blocks) {
  w.tag("BLKS");
  w.value(std::uint64_t(blocks.size()));
  for (const Block& b : blocks) {
    for (int v : b.lo) w.value(std::int32_t(v));
    for (int v : b.hi) w.value(std::int32_t(v));
    w.value(b.strength);
    w.flag(b.intact);
    w.value(b.first_spring);
    w.value(b.spring_count);
  }
}

void write_grips(ByteWriter& w, const World& world) {
  w.tag("GRIP");
  w.value(std::uint64_t(world.grips.size()));
  for (const Grip& g : world.grips)
    for (float v : g.velocity) w.value(v);
  w.column(world.gripped_nodes);
}

constexpr std::size_t kEventBytes = 8 + 4 + 4 + 1 + 1 + 4 + 1;

void write_events(ByteWriter& w, const std::vector<SplitEvent>& events) {
  w.tag("EVNT");
  w.value(std::uint64_t(events.size()));
  for (const SplitEvent& e : events) {
    w.value(std::int64_t(e.step));
    w.value(e.node);
    w.value(e.new_node);
    w.value(e.axis);
    w.flag(e.interlayer);
    w.value(e.cell);
    w.value(e.slot);
  }
}

std::string write_payload(const World& world, std::string_view user_data) {
  ByteWriter w;
  write_scene(w, world.scene);
  write_nodes(w, world.nodes);
  write_topology(w, world.topo);
  write_springs(w, world.springs);
  write_coarse(w, world.coarse);
  write_blocks(w, world.blocks);
  write_grips(w, world);
  write_events(w, world.events);
  w.tag("CLCK");
  w.value(std::int64_t(world.step));
  w.value(world.time);
  w.value(world.dt);
  w.tag("USER");
  w.text(user_data);
  return w.take();
}

// ---------------------------------------------------------------------------------------
// Reading: the same order. Sizes are only read here; whether they agree is checked below.

int read_int(ByteReader& r, const char* what) { return int(r.value<std::int32_t>(what)); }

// The fewest bytes a stored line takes: kind length, point count, strength, depth, pitch, duty.
constexpr std::size_t kLineMinBytes = 8 + 8 + 8 + 4 + 8 + 8;

void read_scene(ByteReader& r, Scene& s) {
  r.section("SCEN");
  for (int& v : s.sheet.cells) v = read_int(r, "sheet.cells");
  r.fixed(s.sheet.cell_size, "sheet.cell_size");
  s.sheet.density = r.value<double>("sheet.density");

  MaterialParams& m = s.material;
  m.preset = r.text("material.preset");
  m.grain = r.letter("material.grain");
  for (double* v : {&m.k_edge, &m.k_face, &m.k_body, &m.damping, &m.grain_stiffness, &m.fiber_length,
                    &m.fiber_length_sigma})
    *v = r.value<double>("a material value");
  m.block_width = read_int(r, "material.block_width");
  m.block_depth = read_int(r, "material.block_depth");
  for (double* v : {&m.block_stiffness, &m.strain_intra, &m.strain_inter, &m.strain_layer, &m.strain_surface,
                    &m.grain_strength, &m.strength_jitter})
    *v = r.value<double>("a material value");

  LoadParams& l = s.load;
  l.kind = r.text("load.kind");
  l.axis = r.letter("load.axis");
  l.grip_cells = read_int(r, "load.grip_cells");
  l.speed = r.value<double>("load.speed");
  l.ramp_time = r.value<double>("load.ramp_time");
  l.grip_margin = read_int(r, "load.grip_margin");
  l.notch = read_int(r, "load.notch");
  l.indenter = r.text("load.indenter");
  for (double* v : {&l.indenter_radius, &l.indenter_angle, &l.indenter_at[0], &l.indenter_at[1], &l.contact_stiffness})
    *v = r.value<double>("an indenter value");

  r.fixed(s.world.gravity, "world.gravity");
  s.world.drag = r.value<double>("world.drag");

  RunParams& run = s.run;
  run.steps = read_int(r, "run.steps");
  run.dt = r.value<double>("run.dt");
  run.dt_safety = r.value<double>("run.dt_safety");
  run.frames = read_int(r, "run.frames");
  run.seed = r.value<std::uint64_t>("run.seed");
  run.max_splits_per_step = read_int(r, "run.max_splits_per_step");

  // Counts are checked against the bytes left before anything is allocated.
  s.lines.resize(std::size_t(r.count(kLineMinBytes, "the line count")));
  for (LineParams& line : s.lines) {
    line.kind = r.text("line.kind");
    line.points.resize(std::size_t(r.count(2 * sizeof(double), "line.points")));
    for (auto& p : line.points) {
      p[0] = r.value<double>("line.points");
      p[1] = r.value<double>("line.points");
    }
    line.strength = r.value<double>("line.strength");
    line.depth = read_int(r, "line.depth");
    line.pitch = r.value<double>("line.pitch");
    line.duty = r.value<double>("line.duty");
  }
}

void read_nodes(ByteReader& r, NodeStore& n) {
  r.section("NODE");
  const std::uint64_t count = r.value<std::uint64_t>("the node count");
  if (count >= std::uint64_t(UINT32_MAX)) inconsistent("node count " + str(count) + " exceeds 32-bit node ids");
  n.count = std::size_t(count);
  const char* names[] = {"px", "py", "pz", "vx", "vy", "vz", "inv_mass", "free_mask", "mass"};
  AlignedArray<float>* cols[] = {&n.px, &n.py, &n.pz, &n.vx, &n.vy, &n.vz, &n.inv_mass, &n.free_mask, &n.mass};
  for (std::size_t i = 0; i < std::size(cols); ++i) r.column(*cols[i], names[i]);
  r.column(n.vertex, "vertex");
  r.column(n.grip, "grip");
}

void read_topology(ByteReader& r, Topology& t) {
  r.section("TOPO");
  t.dims.nx = read_int(r, "dims.nx");
  t.dims.ny = read_int(r, "dims.ny");
  t.dims.nl = read_int(r, "dims.nl");
  t.dims.hx = r.value<double>("dims.hx");
  t.dims.hy = r.value<double>("dims.hy");
  t.dims.hz = r.value<double>("dims.hz");
  r.column(t.cell_nodes, "cell_nodes");
  for (auto& list : t.colour_cells) r.column(list, "colour_cells");
  r.column(t.cell_scale, "cell_scale");
  r.column(t.cell_block, "cell_block");
  r.column(t.face_strain, "face_strain");
}

void read_springs(ByteReader& r, SpringTable& s) {
  r.section("SPRG");
  r.fixed(s.rest, "rest");
  r.fixed(s.stiffness, "stiffness");
  r.fixed(s.damping, "damping");
}

void read_coarse(ByteReader& r, CoarseSprings& c) {
  r.section("CRSE");
  r.column(c.cell_a, "cell_a");
  r.column(c.cell_b, "cell_b");
  r.column(c.corner_a, "corner_a");
  r.column(c.corner_b, "corner_b");
  r.column(c.rest, "rest");
  r.column(c.stiffness, "stiffness");
  r.column(c.damping, "damping");
  r.column(c.block, "block");
}

void read_blocks(ByteReader& r, std::vector<Block>& blocks) {
  r.section("BLKS");
  constexpr std::size_t kBlockBytes = 6 * 4 + 4 + 1 + 4 + 4;
  blocks.resize(std::size_t(r.count(kBlockBytes, "the block count")));
  for (Block& b : blocks) {
    for (int& v : b.lo) v = read_int(r, "block lo");
    for (int& v : b.hi) v = read_int(r, "block hi");
    b.strength = r.value<float>("block strength");
    b.intact = r.flag("block intact");
    b.first_spring = r.value<std::uint32_t>("block first_spring");
    b.spring_count = r.value<std::uint32_t>("block spring_count");
  }
}

void read_grips(ByteReader& r, World& world) {
  r.section("GRIP");
  world.grips.resize(std::size_t(r.count(12, "the grip count")));
  for (Grip& g : world.grips) r.fixed(g.velocity, "grip velocity");
  r.column(world.gripped_nodes, "gripped_nodes");
}

void read_events(ByteReader& r, std::vector<SplitEvent>& events) {
  r.section("EVNT");
  events.resize(std::size_t(r.count(kEventBytes, "the event count")));
  for (SplitEvent& e : events) {
    e.step = r.value<std::int64_t>("event step");
    e.node = r.value<std::uint32_t>("event node");
    e.new_node = r.value<std::uint32_t>("event new_node");
    e.axis = r.value<std::uint8_t>("event axis");
    e.interlayer = r.flag("event interlayer");
    e.cell = r.value<std::uint32_t>("event cell");
    e.slot = r.value<std::uint8_t>("event slot");
  }
}

void read_payload(std::string_view payload, CheckpointContents& out) {
  ByteReader r(payload);
  World& w = out.world;
  read_scene(r, w.scene);
  read_nodes(r, w.nodes);
  read_topology(r, w.topo);
  read_springs(r, w.springs);
  read_coarse(r, w.coarse);
  read_blocks(r, w.blocks);
  read_grips(r, w);
  read_events(r, w.events);
  r.section("CLCK");
  w.step = r.value<std::int64_t>("step");
  w.time = r.value<double>("time");
  w.dt = r.value<double>("dt");
  r.section("USER");
  out.user_data = r.text("user data");
  if (r.remaining() != 0)
    inconsistent(str(r.remaining()) + " bytes follow the last section of the payload");
}

// ---------------------------------------------------------------------------------------
// Consistency: what the solver and the fracture pass index with must be in range, so that a
// crafted or damaged file is refused here rather than crashing a later step.

void check_scene_and_dims(const World& w) {
  try {
    validate(w.scene);
  } catch (const SceneError& e) {
    inconsistent(std::string("the stored scene is invalid: ") + e.what());
  }
  const SheetParams& s = w.scene.sheet;
  const LatticeDims& d = w.topo.dims;
  if (d.nx != s.cells[0] || d.ny != s.cells[1] || d.nl != s.cells[2])
    inconsistent("lattice dims " + std::to_string(d.nx) + " x " + std::to_string(d.ny) + " x " +
                 std::to_string(d.nl) + " disagree with the scene's sheet.cells");
  if (d.hx != s.cell_size[0] || d.hy != s.cell_size[1] || d.hz != s.cell_size[2])
    inconsistent("the lattice cell size disagrees with the scene's sheet.cell_size");
}

void require_size(std::size_t got, std::size_t want, const std::string& what) {
  if (got != want) inconsistent(what + " has " + str(got) + " entries, expected " + str(want));
}

void check_sizes(const World& w) {
  const NodeStore& n = w.nodes;
  const std::size_t nodes = n.count, cells = std::size_t(w.topo.dims.cells());
  if (nodes < std::size_t(w.topo.dims.vertices()))
    inconsistent(str(nodes) + " nodes are fewer than the " + str(std::uint64_t(w.topo.dims.vertices())) +
                 " lattice vertices");
  for (const AlignedArray<float>* c : {&n.px, &n.py, &n.pz, &n.vx, &n.vy, &n.vz, &n.inv_mass, &n.free_mask, &n.mass})
    require_size(c->size(), nodes, "a node column");
  require_size(n.vertex.size(), nodes, "the node vertex column");
  require_size(n.grip.size(), nodes, "the node grip column");
  require_size(w.topo.cell_nodes.size(), cells * 8, "cell_nodes");
  require_size(w.topo.cell_scale.size(), cells, "cell_scale");
  require_size(w.topo.cell_block.size(), cells, "cell_block");
  require_size(w.topo.face_strain.size(), cells * kFacesPerCell, "face_strain");
  const CoarseSprings& c = w.coarse;
  for (std::size_t size : {c.cell_b.size(), c.corner_a.size(), c.corner_b.size(), c.rest.size(),
                           c.stiffness.size(), c.damping.size(), c.block.size()})
    require_size(size, c.cell_a.size(), "a block-spring column");
}

void check_colours(const Topology& t) {
  std::array<std::vector<std::uint32_t>, 8> want;
  const LatticeDims& d = t.dims;
  for (std::uint32_t c = 0; c < std::uint32_t(d.cells()); ++c) {
    const auto ijk = d.cell_ijk(c);
    want[std::size_t(LatticeDims::colour(ijk[0], ijk[1], ijk[2]))].push_back(c);
  }
  for (std::size_t k = 0; k < 8; ++k)
    if (t.colour_cells[k] != want[k]) inconsistent("colour list " + str(k) + " is not the cells of that colour");
}

void check_nodes(const NodeStore& n, std::size_t grips) {
  for (std::size_t i = 0; i < n.count; ++i) {
    if (!std::isfinite(n.vx[i]) || !std::isfinite(n.vy[i]) || !std::isfinite(n.vz[i]) || !std::isfinite(n.inv_mass[i]))
      inconsistent("node " + str(i) + " has a non-finite velocity or inverse mass");
    if (n.grip[i] > grips) inconsistent("node " + str(i) + " names grip " + str(n.grip[i]) + " of " + str(grips));
  }
}

void check_blocks(const World& w) {
  const LatticeDims& d = w.topo.dims;
  const int lim[3] = {d.nx, d.ny, d.nl};
  const std::size_t springs = w.coarse.size();
  for (std::size_t b = 0; b < w.blocks.size(); ++b) {
    const Block& blk = w.blocks[b];
    for (std::size_t a = 0; a < 3; ++a)
      if (blk.lo[a] < 0 || blk.lo[a] >= blk.hi[a] || blk.hi[a] > lim[a])
        inconsistent("block " + str(b) + " is not a box of cells inside the lattice");
    if (std::uint64_t(blk.first_spring) + blk.spring_count > springs)
      inconsistent("block " + str(b) + " names block springs beyond the " + str(springs) + " stored");
    for (std::uint32_t i = blk.first_spring; i < blk.first_spring + blk.spring_count; ++i)
      if (w.coarse.block[i] != b) inconsistent("block spring " + str(i) + " does not belong to block " + str(b));
  }
  for (std::size_t c = 0; c < w.topo.cell_block.size(); ++c)
    if (w.topo.cell_block[c] >= w.blocks.size())
      inconsistent("cell " + str(c) + " names block " + str(w.topo.cell_block[c]) + " of " + str(w.blocks.size()));
}

void check_grips(const World& w) {
  for (const Grip& g : w.grips)
    for (float v : g.velocity)
      if (!std::isfinite(v)) inconsistent("a grip has a non-finite velocity");
  std::vector<std::uint32_t> want;
  for (std::uint32_t n = 0; n < w.nodes.count; ++n)
    if (w.nodes.grip[n] != 0) want.push_back(n);
  if (w.gripped_nodes != want) inconsistent("the gripped-node list disagrees with the nodes' grips");
}

void check_events_and_clock(const World& w) {
  if (w.step < 0) inconsistent("negative step count " + std::to_string(w.step));
  if (!std::isfinite(w.time)) inconsistent("non-finite simulated time");
  if (!(std::isfinite(w.dt) && w.dt > 0.0)) inconsistent("the time step is not a positive finite number");
  const std::size_t cells = std::size_t(w.topo.dims.cells());
  for (std::size_t i = 0; i < w.events.size(); ++i) {
    const SplitEvent& e = w.events[i];
    const bool ok = e.step >= 1 && e.step <= w.step && e.node < w.nodes.count && e.new_node < w.nodes.count &&
                    e.axis < 3 && e.interlayer == (e.axis == 2) && e.cell < cells && e.slot < kEdgesPerCell;
    if (!ok) inconsistent("split event " + str(i) + " names a step, node, cell or spring out of range");
  }
}

void check_world(const World& w) {
  check_scene_and_dims(w);
  check_sizes(w);
  check_colours(w.topo);
  check_nodes(w.nodes, w.grips.size());
  check_blocks(w);
  check_grips(w);
  check_events_and_clock(w);
  const std::vector<std::string> problems = check_invariants(w, 4);
  if (!problems.empty()) {
    std::string all = problems.front();
    for (std::size_t i = 1; i < problems.size(); ++i) all += "; " + problems[i];
    inconsistent("invariants do not hold: " + all);
  }
}

// ---------------------------------------------------------------------------------------

void check_header(std::string_view bytes, std::string_view& payload) {
  const std::size_t magic_seen = std::min(bytes.size(), kCheckpointMagic.size());
  if (bytes.substr(0, magic_seen) != kCheckpointMagic.substr(0, magic_seen) || bytes.empty())
    fail(Kind::NotACheckpoint, "the file does not start with the checkpoint magic bytes");
  if (bytes.size() < kCheckpointHeaderSize)
    fail(Kind::Truncated, "the " + str(kCheckpointHeaderSize) + "-byte header is cut off after " +
                              str(bytes.size()) + " bytes");
  const auto version = get_le<std::uint32_t>(bytes.data() + 8);
  if (version != kCheckpointFormatVersion)
    fail(Kind::WrongVersion, "written by format version " + str(version) + ", this build reads version " +
                                 str(kCheckpointFormatVersion));
  const auto length = get_le<std::uint64_t>(bytes.data() + 16);
  const auto checksum = get_le<std::uint64_t>(bytes.data() + 24);
  const std::size_t have = bytes.size() - kCheckpointHeaderSize;
  if (length > have)
    fail(Kind::Truncated, "the header promises " + str(length) + " payload bytes, the file holds " + str(have));
  if (length < have)
    fail(Kind::Corrupted, str(have - length) + " unexpected bytes follow the " + str(length) + "-byte payload");
  payload = bytes.substr(kCheckpointHeaderSize);
  const std::uint64_t got = checkpoint_checksum(payload);
  if (got != checksum) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "payload checksum %016llx does not match the header's %016llx",
                  static_cast<unsigned long long>(got), static_cast<unsigned long long>(checksum));
    fail(Kind::Corrupted, buf);
  }
}

[[noreturn]] void io_error(const std::string& path, const std::string& what) {
  throw CheckpointError(Kind::Io, path + ": " + what + " (" + std::strerror(errno) + ")");
}

std::string read_file(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f) io_error(path, "cannot open the checkpoint");
  std::string bytes;
  char buf[1 << 16];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, f.get())) > 0) bytes.append(buf, n);
  if (std::ferror(f.get())) io_error(path, "cannot read the checkpoint");
  return bytes;
}

// Every error names its origin: "checkpoint" in memory, the path for a file.
CheckpointContents parse_checkpoint(std::string_view bytes, const std::string& origin) {
  try {
    std::string_view payload;
    check_header(bytes, payload);
    CheckpointContents out;
    read_payload(payload, out);
    check_world(out.world);
    reset_stage_state(out.world);
    return out;
  } catch (const CheckpointError& e) {
    throw CheckpointError(e.kind, origin + ": " + e.what());
  }
}

}  // namespace

const char* checkpoint_error_name(CheckpointError::Kind kind) {
  switch (kind) {
    case Kind::NotACheckpoint: return "not a papertear checkpoint";
    case Kind::WrongVersion: return "unsupported checkpoint format version";
    case Kind::Truncated: return "truncated checkpoint";
    case Kind::Corrupted: return "corrupted checkpoint";
    case Kind::Inconsistent: return "inconsistent checkpoint contents";
    case Kind::Io: return "checkpoint file error";
  }
  return "checkpoint error";
}

std::uint64_t checkpoint_checksum(std::string_view payload) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (char c : payload) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001b3ull;
  return h;
}

std::string serialize_world(const World& world, std::string_view user_data) {
  const std::string payload = write_payload(world, user_data);
  std::string out(kCheckpointMagic);
  put_le(out, kCheckpointFormatVersion);
  put_le(out, std::uint32_t(0));
  put_le(out, std::uint64_t(payload.size()));
  put_le(out, checkpoint_checksum(payload));
  out += payload;
  return out;
}

CheckpointContents deserialize_checkpoint(std::string_view bytes) { return parse_checkpoint(bytes, "checkpoint"); }

World deserialize_world(std::string_view bytes) { return std::move(deserialize_checkpoint(bytes).world); }

void save_checkpoint(const World& world, const std::string& path, std::string_view user_data) {
  try {
    write_file_atomically(path, serialize_world(world, user_data));
  } catch (const FileWriteError& e) {
    throw CheckpointError(Kind::Io, std::string("cannot save the checkpoint: ") + e.what());
  }
}

CheckpointContents read_checkpoint(const std::string& path) { return parse_checkpoint(read_file(path), path); }

World load_checkpoint(const std::string& path) { return std::move(read_checkpoint(path).world); }

}  // namespace papertear
