#include "tools/sweep_file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/input_file.hpp"
#include "tools/summary.hpp"
#include "tools/toml_keys.hpp"

namespace papertear::io {
namespace {

const std::vector<std::string>& sweep_keys() {
  static const std::vector<std::string> keys = {"scene", "seeds", "set", "grid", "point"};
  return keys;
}

toml::table parse_sweep_document(std::string_view text, const std::filesystem::path& path) {
  try {
    return toml::parse(text, path.string());
  } catch (const toml::parse_error& e) {
    const auto& begin = e.source().begin;
    throw SceneError(path.string() + ":" + std::to_string(begin.line) + ":" +
                     std::to_string(begin.column) + ": TOML syntax error: " + std::string(e.description()));
  }
}

// --- values ----------------------------------------------------------------------------

// The shortest text that reads back as the same double, always with a '.' or an exponent
// so that TOML reads a float, not an integer.
std::string float_text(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, end);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

// Fills `out` with the node as TOML text and JSON. Throws for dates, times and tables.
void convert(const toml::node& node, std::string_view key, std::string& text, nlohmann::json& json) {
  if (auto v = node.as_integer()) {
    text = std::to_string(v->get());
    json = v->get();
  } else if (auto f = node.as_floating_point()) {
    text = float_text(f->get());
    json = f->get();
  } else if (auto b = node.as_boolean()) {
    text = b->get() ? "true" : "false";
    json = b->get();
  } else if (auto s = node.as_string()) {
    text = quoted(s->get());
    json = s->get();
  } else if (auto a = node.as_array()) {
    text = "[";
    json = nlohmann::json::array();
    for (std::size_t i = 0; i < a->size(); ++i) {
      std::string t;
      nlohmann::json j;
      convert(*a->get(i), key, t, j);
      text += (i ? ", " : "") + t;
      json.push_back(std::move(j));
    }
    text += "]";
  } else {
    fail_at(node, key, "expected a number, string, boolean or array, got " + type_phrase(node));
  }
}

SweepValue make_value(std::string key, const toml::node& node) {
  SweepValue v;
  convert(node, key, v.toml, v.json);
  v.key = std::move(key);
  v.where = where(node);
  return v;
}

// --- tables of dotted keys -------------------------------------------------------------

struct Leaf {
  std::string key;
  const toml::node* node;
};

// The non-table values under `table` with their dotted keys, in the order they were written
// (toml++ keeps keys sorted, but every node remembers where it came from).
std::vector<Leaf> leaves(const toml::table& table, const std::string& prefix = "") {
  std::vector<Leaf> out;
  for (const auto& [k, node] : table) {
    std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = node.as_table()) {
      std::vector<Leaf> inner = leaves(*sub, key);
      out.insert(out.end(), inner.begin(), inner.end());
    } else {
      out.push_back({std::move(key), &node});
    }
  }
  std::stable_sort(out.begin(), out.end(), [](const Leaf& a, const Leaf& b) {
    const auto& pa = a.node->source().begin;
    const auto& pb = b.node->source().begin;
    return std::pair(pa.line, pa.column) < std::pair(pb.line, pb.column);
  });
  return out;
}

// A key of [set], [grid] or [[point]] must be a scene key; `seeds` owns run.seed.
void check_scene_key(const Leaf& leaf, std::string_view section, bool seeded) {
  const auto& known = scene_keys();
  if (std::find(known.begin(), known.end(), leaf.key) == known.end()) {
    std::string message = std::string(section) + ": unknown scene key '" + leaf.key + "'";
    if (auto near = nearest_key(leaf.key, known)) message += " (did you mean '" + *near + "'?)";
    fail_at(*leaf.node, "", message);
  }
  if (seeded && leaf.key == "run.seed")
    fail_at(*leaf.node, "", std::string(section) +
                                ": run.seed is set by `seeds`; list the seeds there or drop `seeds`");
}

std::vector<SweepValue> read_overrides(const toml::table& table, std::string_view section, bool seeded) {
  std::vector<SweepValue> out;
  for (const Leaf& leaf : leaves(table)) {
    check_scene_key(leaf, section, seeded);
    out.push_back(make_value(leaf.key, *leaf.node));
  }
  return out;
}

std::string section_where(const toml::node& node, const std::filesystem::path& path) {
  std::string w = where(node);
  return w.empty() ? path.string() : w;
}

// --- points ----------------------------------------------------------------------------

struct GridAxis {
  std::string key;
  std::vector<SweepValue> values;
};

std::vector<GridAxis> read_grid(const toml::table& grid, const std::filesystem::path& path, bool seeded) {
  std::vector<GridAxis> axes;
  for (const Leaf& leaf : leaves(grid)) {
    check_scene_key(leaf, "[grid]", seeded);
    const toml::array* list = leaf.node->as_array();
    if (!list)
      fail_at(*leaf.node, "[grid] " + leaf.key,
              "expected a list of values, got " + type_phrase(*leaf.node) + " (put a single value in [set])");
    if (list->empty()) fail_at(*leaf.node, "[grid] " + leaf.key, "the list of values is empty");
    GridAxis axis{leaf.key, {}};
    for (const toml::node& v : *list) axis.values.push_back(make_value(leaf.key, v));
    axes.push_back(std::move(axis));
  }
  if (axes.empty()) throw SceneError(section_where(grid, path) + ": [grid] is empty");
  return axes;
}

std::vector<std::vector<SweepValue>> grid_combinations(const std::vector<GridAxis>& axes,
                                                       const std::filesystem::path& path) {
  std::size_t count = 1;
  for (const GridAxis& a : axes) {
    count *= a.values.size();
    if (count > kMaxSweepPoints)
      throw SceneError(path.string() + ": [grid] has more than " + std::to_string(kMaxSweepPoints) + " points");
  }
  std::vector<std::vector<SweepValue>> out;
  for (std::size_t n = 0; n < count; ++n) {
    std::vector<SweepValue> combo(axes.size());
    std::size_t rest = n;
    for (std::size_t a = axes.size(); a-- > 0;) {  // the last key varies fastest
      combo[a] = axes[a].values[rest % axes[a].values.size()];
      rest /= axes[a].values.size();
    }
    out.push_back(std::move(combo));
  }
  return out;
}

std::vector<std::vector<SweepValue>> point_tables(const toml::node& node, const std::filesystem::path& path,
                                                  bool seeded) {
  const toml::array* list = node.as_array();
  if (!list || !list->is_array_of_tables())
    fail_at(node, "point", "expected [[point]] tables, got " + type_phrase(node));
  if (list->empty()) fail_at(node, "point", "the list of points is empty");
  // Counted before any point is read, as grid_combinations does.
  if (list->size() > kMaxSweepPoints)
    throw SceneError(path.string() + ": more than " + std::to_string(kMaxSweepPoints) + " points");
  std::vector<std::vector<SweepValue>> out;
  for (const toml::node& t : *list) out.push_back(read_overrides(*t.as_table(), "[[point]]", seeded));
  return out;
}

std::vector<std::uint64_t> read_seeds(const toml::node& node) {
  const toml::array* list = node.as_array();
  if (!list) fail_at(node, "seeds", "expected a list of seeds such as [1, 2, 3], got " + type_phrase(node));
  if (list->empty()) fail_at(node, "seeds", "the list of seeds is empty");
  std::vector<std::uint64_t> seeds;
  for (const toml::node& s : *list) seeds.push_back(read_unsigned(s, "seeds"));
  return seeds;
}

// The swept keys: the grid's, or every key some [[point]] sets, in order of appearance.
std::vector<std::string> swept_keys(const std::vector<std::vector<SweepValue>>& combos) {
  std::vector<std::string> keys;
  for (const auto& combo : combos)
    for (const SweepValue& v : combo)
      if (std::find(keys.begin(), keys.end(), v.key) == keys.end()) keys.push_back(v.key);
  return keys;
}

std::string base_scene(const toml::table& doc, const std::filesystem::path& path) {
  const toml::node* node = doc.get("scene");
  if (!node) return {};
  std::string scene = read_string(*node, "scene");
  if (scene.empty()) fail_at(*node, "scene", "the scene path is empty");
  std::filesystem::path p(scene);
  if (p.is_relative()) p = path.parent_path() / p;
  return p.lexically_normal().string();
}

std::uint64_t fnv1a(std::string_view bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace

SweepDefinition load_sweep(const std::filesystem::path& path) {
  std::string text;
  try {
    text = read_input_file(path.string(), kSweepFileKind);
  } catch (const InputFileError& e) {
    throw SceneError(e.what());
  }
  return parse_sweep(text, path);
}

SweepDefinition parse_sweep(std::string_view text, const std::filesystem::path& path) {
  const toml::table doc = parse_sweep_document(text, path);
  check_known_keys(doc, "", sweep_keys());
  SweepDefinition sweep;
  sweep.path = path;
  sweep.scene_path = base_scene(doc, path);
  std::vector<std::uint64_t> seeds;
  if (const toml::node* s = doc.get("seeds")) seeds = read_seeds(*s);
  sweep.seeded = !seeds.empty();
  if (const toml::table* set = find_table(doc, "set", "set"))
    sweep.common = read_overrides(*set, "[set]", sweep.seeded);

  const toml::table* grid = find_table(doc, "grid", "grid");
  const toml::node* points = doc.get("point");
  if (grid && points) fail_at(*points, "point", "give either [grid] or [[point]] tables, not both");
  std::vector<std::vector<SweepValue>> combos = {{}};  // neither: one point, the base scene
  if (grid) combos = grid_combinations(read_grid(*grid, path, sweep.seeded), path);
  if (points) combos = point_tables(*points, path, sweep.seeded);
  sweep.keys = swept_keys(combos);

  const std::size_t per_combo = sweep.seeded ? seeds.size() : 1;
  if (combos.size() * per_combo > kMaxSweepPoints)
    throw SceneError(path.string() + ": more than " + std::to_string(kMaxSweepPoints) + " points");
  for (const auto& combo : combos)
    for (std::size_t s = 0; s < per_combo; ++s) {
      SweepPoint p{static_cast<int>(sweep.points.size()), combo, std::nullopt};
      if (sweep.seeded) p.seed = seeds[s];
      sweep.points.push_back(std::move(p));
    }
  return sweep;
}

std::vector<SetOverride> point_overrides(const SweepDefinition& sweep, const SweepPoint& p) {
  std::vector<SetOverride> out;
  for (const SweepValue& v : sweep.common) out.push_back({v.key, v.toml, {}});
  for (const SweepValue& v : p.values) out.push_back({v.key, v.toml, {}});
  if (p.seed) out.push_back({"run.seed", std::to_string(*p.seed), {}});
  return out;
}

SceneFile resolve_point(const SweepDefinition& sweep, const SweepPoint& p) {
  const std::vector<SetOverride> overrides = point_overrides(sweep, p);
  try {
    if (sweep.scene_path.empty()) return default_scene_file(overrides);
    return load_scene_file(sweep.scene_path, overrides);
  } catch (const SceneError& e) {
    throw SceneError(sweep.path.string() + ": point " + std::to_string(p.index) + ": " + e.what());
  }
}

std::uint64_t sweep_hash(const SweepDefinition& sweep, std::span<const SceneFile> scenes) {
  std::string text = "papertear-sweep 1\n";
  for (const SweepPoint& p : sweep.points) {
    text += "point " + std::to_string(p.index) + "\n";
    for (const SetOverride& o : point_overrides(sweep, p)) text += o.argument() + "\n";
    text += scene_to_json(scenes[static_cast<std::size_t>(p.index)].scene).dump() + "\n";
  }
  return fnv1a(text);
}

}  // namespace papertear::io
