#include "core/checkpoint.hpp"

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <type_traits>
#include <vector>

#include "core/atomic_file.hpp"
#include "core/input_file.hpp"
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

// The payload's fields are listed once (the *_fields templates below) for both directions:
// ByteWriter and ByteReader have the same field functions, the writer's taking values to
// store and the reader's references to fill. `what` names a field in the reader's errors.
class ByteWriter {
 public:
  static constexpr bool kReading = false;

  void section(std::string_view t) { out_.append(t); }
  // A value stored as type F (for example an int as int32).
  template <class F, class T>
  void field_as(const T& v, const char*) { put_le(out_, F(v)); }
  template <class T>
  void field(const T& v, const char* what) { field_as<T>(v, what); }
  void int32(int v, const char* what) { field_as<std::int32_t>(v, what); }
  void flag(bool b, const char* what) { field_as<std::uint8_t>(b ? 1 : 0, what); }
  void letter(char c, const char* what) { field_as<std::uint8_t>(static_cast<unsigned char>(c), what); }
  void text(std::string_view s, const char* what) {
    field_as<std::uint64_t>(s.size(), what);
    out_.append(s);
  }
  template <class T, std::size_t N>
  void fixed(const std::array<T, N>& a, const char* what) {
    for (const T& v : a) field(v, what);
  }
  template <class C>
  void column(const C& c, const char* what) {
    using T = std::remove_cvref_t<decltype(c[0])>;
    field_as<std::uint64_t>(c.size(), what);
    if constexpr (std::endian::native == std::endian::little) {
      out_.append(reinterpret_cast<const char*>(c.data()), c.size() * sizeof(T));
    } else {
      for (const T& v : c) put_le(out_, v);
    }
  }
  // A count, then each element by `element(e)`.
  template <class E, class Element>
  void list(const std::vector<E>& v, std::size_t, const char* what, const Element& element) {
    field_as<std::uint64_t>(v.size(), what);
    for (const E& e : v) element(e);
  }
  std::string take() { return std::move(out_); }

 private:
  std::string out_;
};

class ByteReader {
 public:
  static constexpr bool kReading = true;

  explicit ByteReader(std::string_view bytes) : all_(bytes), rest_(bytes) {}

  void section(std::string_view t) {
    section_ = std::string(t);
    const std::string_view got = take(t.size(), "the section tag");
    if (got != t)
      inconsistent("expected section " + section_ + " at payload offset " + str(offset() - t.size()));
  }
  template <class T>
  T value(const char* what) { return get_le<T>(take(sizeof(T), what).data()); }
  template <class F, class T>
  void field_as(T& v, const char* what) { v = T(value<F>(what)); }
  template <class T>
  void field(T& v, const char* what) { v = value<T>(what); }
  void int32(int& v, const char* what) { v = int(value<std::int32_t>(what)); }
  void flag(bool& out, const char* what) {
    const auto b = value<std::uint8_t>(what);
    if (b > 1) inconsistent(std::string(what) + " in section " + section_ + " is " + str(b) + ", not 0 or 1");
    out = b == 1;
  }
  void letter(char& c, const char* what) { c = static_cast<char>(value<std::uint8_t>(what)); }
  void text(std::string& s, const char* what) {
    const std::uint64_t n = count(1, what);
    s = std::string(take(std::size_t(n), what));
  }
  // A count, checked against the bytes left (each element takes at least `min_bytes`)
  // before anything is allocated, then each element by `element(e)`.
  template <class E, class Element>
  void list(std::vector<E>& v, std::size_t min_bytes, const char* what, const Element& element) {
    v.resize(std::size_t(count(min_bytes, what)));
    for (E& e : v) element(e);
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
    for (T& v : out) field(v, what);
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
// The payload, field by field, for writing (IO = ByteWriter, const structs) and reading
// (IO = ByteReader). A field added to a struct must be added here and the format version
// bumped. Sizes are only read here; whether they agree is checked below.

template <class IO, class S>
void scene_fields(IO& io, S& s) {
  io.section("SCEN");
  for (auto& v : s.sheet.cells) io.int32(v, "sheet.cells");
  io.fixed(s.sheet.cell_size, "sheet.cell_size");

  auto& m = s.material;
  io.text(m.preset, "material.preset");
  io.letter(m.grain, "material.grain");
  for (auto* v : {&m.E_md, &m.E_cd, &m.E_zd, &m.G_md_cd, &m.G_md_zd, &m.G_cd_zd, &m.density, &m.damping,
                  &m.fiber_length, &m.fiber_length_sigma})
    io.field(*v, "a material value");
  io.int32(m.block_width, "material.block_width");
  io.int32(m.block_depth, "material.block_depth");
  for (auto* v : {&m.block_stiffness, &m.strain_intra, &m.strain_inter, &m.strain_layer, &m.strain_surface,
                  &m.grain_strength, &m.cross_stretch, &m.strength_jitter, &m.tip_strength, &m.bridge_time})
    io.field(*v, "a material value");

  auto& l = s.load;
  io.text(l.kind, "load.kind");
  io.letter(l.axis, "load.axis");
  io.int32(l.grip_cells, "load.grip_cells");
  io.field(l.speed, "load.speed");
  io.field(l.ramp_time, "load.ramp_time");
  io.int32(l.grip_margin, "load.grip_margin");
  io.int32(l.notch, "load.notch");
  io.text(l.indenter, "load.indenter");
  for (auto* v : {&l.indenter_radius, &l.indenter_angle, &l.indenter_at[0], &l.indenter_at[1], &l.contact_stiffness})
    io.field(*v, "an indenter value");

  io.fixed(s.world.gravity, "world.gravity");
  io.field(s.world.drag, "world.drag");

  auto& run = s.run;
  io.int32(run.steps, "run.steps");
  io.field(run.dt, "run.dt");
  io.field(run.dt_safety, "run.dt_safety");
  io.int32(run.frames, "run.frames");
  io.template field_as<std::uint64_t>(run.seed, "run.seed");
  io.int32(run.max_splits_per_step, "run.max_splits_per_step");

  // The fewest bytes a stored line takes: kind length, point count, strength, depth, pitch, duty.
  constexpr std::size_t kLineMinBytes = 8 + 8 + 8 + 4 + 8 + 8;
  io.list(s.lines, kLineMinBytes, "the line count", [&](auto& line) {
    io.text(line.kind, "line.kind");
    io.list(line.points, 2 * sizeof(double), "line.points", [&](auto& p) {
      io.field(p[0], "line.points");
      io.field(p[1], "line.points");
    });
    io.field(line.strength, "line.strength");
    io.int32(line.depth, "line.depth");
    io.field(line.pitch, "line.pitch");
    io.field(line.duty, "line.duty");
  });
}

template <class IO, class N>
void node_fields(IO& io, N& n) {
  io.section("NODE");
  std::uint64_t count = n.count;
  io.field(count, "the node count");
  if constexpr (IO::kReading) {
    if (count >= std::uint64_t(UINT32_MAX)) inconsistent("node count " + str(count) + " exceeds 32-bit node ids");
    n.count = std::size_t(count);
  }
  io.column(n.px, "px");
  io.column(n.py, "py");
  io.column(n.pz, "pz");
  io.column(n.vx, "vx");
  io.column(n.vy, "vy");
  io.column(n.vz, "vz");
  io.column(n.inv_mass, "inv_mass");
  io.column(n.free_mask, "free_mask");
  io.column(n.mass, "mass");
  io.column(n.vertex, "vertex");
  io.column(n.grip, "grip");
}

template <class IO, class T>
void topology_fields(IO& io, T& t) {
  io.section("TOPO");
  io.int32(t.dims.nx, "dims.nx");
  io.int32(t.dims.ny, "dims.ny");
  io.int32(t.dims.nl, "dims.nl");
  io.field(t.dims.hx, "dims.hx");
  io.field(t.dims.hy, "dims.hy");
  io.field(t.dims.hz, "dims.hz");
  io.column(t.cell_nodes, "cell_nodes");
  for (auto& list : t.colour_cells) io.column(list, "colour_cells");
  io.column(t.cell_scale, "cell_scale");
  io.column(t.cell_block, "cell_block");
  io.column(t.face_strain, "face_strain");
  io.column(t.face_damage, "face_damage");
}

template <class IO, class S>
void spring_fields(IO& io, S& s) {
  io.section("SPRG");
  io.fixed(s.rest, "rest");
  io.fixed(s.stiffness, "stiffness");
  io.fixed(s.damping, "damping");
}

template <class IO, class C>
void coarse_fields(IO& io, C& c) {
  io.section("CRSE");
  io.column(c.cell_a, "cell_a");
  io.column(c.cell_b, "cell_b");
  io.column(c.corner_a, "corner_a");
  io.column(c.corner_b, "corner_b");
  io.column(c.rest, "rest");
  io.column(c.stiffness, "stiffness");
  io.column(c.damping, "damping");
  io.column(c.block, "block");
}

template <class IO, class B>
void block_fields(IO& io, B& blocks) {
  io.section("BLKS");
  constexpr std::size_t kBlockBytes = 6 * 4 + 4 + 1 + 4 + 4;
  io.list(blocks, kBlockBytes, "the block count", [&](auto& b) {
    for (auto& v : b.lo) io.int32(v, "block lo");
    for (auto& v : b.hi) io.int32(v, "block hi");
    io.field(b.strength, "block strength");
    io.flag(b.intact, "block intact");
    io.field(b.first_spring, "block first_spring");
    io.field(b.spring_count, "block spring_count");
  });
}

template <class IO, class W>
void grip_fields(IO& io, W& world) {
  io.section("GRIP");
  io.list(world.grips, 12, "the grip count", [&](auto& g) { io.fixed(g.velocity, "grip velocity"); });
  io.column(world.gripped_nodes, "gripped_nodes");
}

constexpr std::size_t kEventBytes = 8 + 4 + 4 + 1 + 1 + 4 + 1;

template <class IO, class E>
void event_fields(IO& io, E& events) {
  io.section("EVNT");
  io.list(events, kEventBytes, "the event count", [&](auto& e) {
    io.template field_as<std::int64_t>(e.step, "event step");
    io.field(e.node, "event node");
    io.field(e.new_node, "event new_node");
    io.field(e.axis, "event axis");
    io.flag(e.interlayer, "event interlayer");
    io.field(e.cell, "event cell");
    io.field(e.slot, "event slot");
  });
}

// The whole payload: the world's parts, its clock, then the caller's bytes.
template <class IO, class W, class U>
void payload_fields(IO& io, W& w, U& user_data) {
  scene_fields(io, w.scene);
  node_fields(io, w.nodes);
  topology_fields(io, w.topo);
  spring_fields(io, w.springs);
  coarse_fields(io, w.coarse);
  block_fields(io, w.blocks);
  grip_fields(io, w);
  event_fields(io, w.events);
  io.section("CLCK");
  io.template field_as<std::int64_t>(w.step, "step");
  io.field(w.time, "time");
  io.field(w.dt, "dt");
  io.section("USER");
  io.text(user_data, "user data");
}

std::string write_payload(const World& world, std::string_view user_data) {
  ByteWriter w;
  payload_fields(w, world, user_data);
  return w.take();
}

void read_payload(std::string_view payload, CheckpointContents& out) {
  ByteReader r(payload);
  payload_fields(r, out.world, out.user_data);
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
  require_size(w.topo.face_damage.size(), cells * kFacesPerCell, "face_damage");
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

std::string read_file(const std::string& path) {
  try {
    return read_input_file(path, kCheckpointKind);
  } catch (const InputFileError& e) {
    throw CheckpointError(Kind::Io, e.what());
  }
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
