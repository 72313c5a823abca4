#include "tools/scene_file.hpp"

#include <cctype>
#include <filesystem>
#include <sstream>

#include "core/input_file.hpp"
#include "tools/scene_fields.hpp"
#include "tools/toml_keys.hpp"

namespace papertear::io {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

bool is_bare_key(std::string_view part) {
  if (part.empty()) return false;
  for (char c : part)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') return false;
  return true;
}

// A word the user meant as a string but did not quote: no TOML punctuation, no spaces, and
// not starting like a number (a mistyped number should be an error, not a string).
bool is_bare_word(std::string_view v) {
  if (v.empty() || std::isdigit(static_cast<unsigned char>(v[0])) || v[0] == '+' || v[0] == '-')
    return false;
  for (char c : v)
    if (std::isspace(static_cast<unsigned char>(c)) || std::strchr("\"'#=[]{},\\", c)) return false;
  return true;
}

std::vector<std::string> split_key(std::string_view key) {
  std::vector<std::string> parts;
  std::istringstream in{std::string(key)};
  for (std::string part; std::getline(in, part, '.');) parts.push_back(part);
  if (!key.empty() && key.back() == '.') parts.emplace_back();
  return parts;
}

toml::table parse_document(std::string_view text, std::string_view source_name) {
  try {
    return toml::parse(text, source_name);
  } catch (const toml::parse_error& e) {
    const auto& begin = e.source().begin;
    std::string place = source_name.empty() ? "scene" : std::string(source_name);
    throw SceneError(place + ":" + std::to_string(begin.line) + ":" + std::to_string(begin.column) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
}

// Parses an override's value as the right-hand side of a TOML assignment.
toml::table parse_override_value(const SetOverride& o) {
  std::string source = o.source();
  toml::table parsed;
  try {
    parsed = toml::parse("value = " + o.value, source);
  } catch (const toml::parse_error& e) {
    if (!is_bare_word(o.value))
      throw SceneError(source + ": not a TOML value (" + std::string(e.description()) +
                       "); quote a string like key='\"text\"'");
    parsed = toml::parse("value = \"" + o.value + "\"", source);
  }
  // "1\nother = 2" would smuggle in a second key.
  if (parsed.size() != 1 || !parsed.contains("value"))
    throw SceneError(source + ": the value must be a single TOML value");
  return parsed;
}

const std::vector<std::string>& all_known_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k = scene_keys();
    k.insert(k.end(), renderer_sections().begin(), renderer_sections().end());
    return k;
  }();
  return keys;
}

// --- reading fields --------------------------------------------------------------------

void read_into(const toml::node& n, std::string_view key, int& out) { out = read_int(n, key); }
void read_into(const toml::node& n, std::string_view key, double& out) { out = read_number(n, key); }
void read_into(const toml::node& n, std::string_view key, std::uint64_t& out) {
  out = read_unsigned(n, key);
}
void read_into(const toml::node& n, std::string_view key, std::string& out) {
  out = read_string(n, key);
}
void read_into(const toml::node& n, std::string_view key, char& out) { out = read_letter(n, key); }
void read_into(const toml::node& n, std::string_view key, std::array<int, 3>& out) {
  out = read_int3(n, key);
}
void read_into(const toml::node& n, std::string_view key, std::array<double, 3>& out) {
  out = read_number3(n, key);
}
void read_into(const toml::node& n, std::string_view key, std::array<double, 2>& out) {
  out = read_number2(n, key);
}
void read_into(const toml::node& n, std::string_view key, AutoOrNumber<double> out) {
  if (auto s = n.as_string()) {
    if (s->get() != "auto") fail_at(n, key, "expected a number or \"auto\", got " + type_phrase(n));
    out.value = 0.0;
    return;
  }
  if (!n.is_number()) fail_at(n, key, "expected a number or \"auto\", got " + type_phrase(n));
  out.value = read_number(n, key);
}

void read_into(const toml::node& n, std::string_view key, std::vector<std::array<double, 2>>& out) {
  const toml::array* arr = n.as_array();
  if (!arr) fail_at(n, key, "expected an array of [x, y] points, got " + type_phrase(n));
  out.clear();
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const toml::node& point = (*arr)[i];
    const std::string name = std::string(key) + "[" + std::to_string(i) + "]";
    const toml::array* xy = point.as_array();
    if (!xy || xy->size() != 2) fail_at(point, name, "expected a point [x, y], got " + type_phrase(point));
    out.push_back({read_number((*xy)[0], name + "[0]"), read_number((*xy)[1], name + "[1]")});
  }
}

// [[line]]: an array of tables, each checked for unknown keys like the rest of the file.
void read_into(const toml::node& n, std::string_view key, std::vector<LineParams>& out) {
  const toml::array* arr = n.as_array();
  if (!arr) fail_at(n, key, "expected an array of tables ([[line]]), got " + type_phrase(n));
  out.clear();
  for (std::size_t i = 0; i < arr->size(); ++i) {
    const std::string name = line_name(i);
    const toml::table* table = (*arr)[i].as_table();
    if (!table) fail_at((*arr)[i], name, "expected a table, got " + type_phrase((*arr)[i]));
    std::vector<std::string> known;
    const LineParams defaults;
    visit_line_fields(defaults, [&](std::string_view field, auto&&) { known.push_back(name + "." + std::string(field)); });
    check_known_keys(*table, name, known);
    LineParams line;
    visit_line_fields(line, [&](std::string_view field, auto&& value) {
      if (const toml::node* node = table->get(field)) read_into(*node, name + "." + std::string(field), value);
    });
    out.push_back(std::move(line));
  }
}

// Re-throws a core SceneError ("<key>: <problem>") with the place the key was written.
[[noreturn]] void rethrow_located(const SceneError& e, const toml::table& doc,
                                  std::string_view source_name) {
  std::string message = e.what();
  // The key is the message's leading dotted name ("sheet.cells[0] (nx): ..." -> sheet.cells).
  std::size_t end = 0;
  while (end < message.size() && (std::isalnum(static_cast<unsigned char>(message[end])) ||
                                  message[end] == '_' || message[end] == '.' || message[end] == '[' ||
                                  message[end] == ']'))
    ++end;
  std::string key = message.substr(0, end);
  if (const toml::node* node = doc.at_path(key).node(); node && !where(*node).empty())
    throw SceneError(where(*node) + ": " + message);
  if (!source_name.empty()) throw SceneError(std::string(source_name) + ": " + message);
  throw;
}

Scene read_scene(const toml::table& doc, std::string_view source_name) {
  Scene scene;
  try {
    if (const toml::node* preset = doc.at_path("material.preset").node())
      apply_material_preset(scene.material, read_string(*preset, "material.preset"));
  } catch (const SceneError& e) {
    rethrow_located(e, doc, source_name);
  }
  visit_scene_fields(scene, [&](std::string_view key, auto&& field) {
    if (const toml::node* node = doc.at_path(key).node()) read_into(*node, key, field);
  });
  try {
    validate(scene);
  } catch (const SceneError& e) {
    rethrow_located(e, doc, source_name);
  }
  return scene;
}

toml::table take_renderer_sections(toml::table& doc) {
  toml::table out;
  for (const std::string& name : renderer_sections()) {
    toml::node* node = doc.get(name);
    if (!node) continue;
    if (!node->is_table()) fail_at(*node, name, "expected a table, got " + type_phrase(*node));
    out.insert(name, std::move(*node->as_table()));  // a move keeps the source locations
  }
  return out;
}

// --- writing fields --------------------------------------------------------------------

toml::table& section_of(toml::table& root, std::string_view key) {
  std::string section(key.substr(0, key.find('.')));
  return *root.emplace<toml::table>(section).first->second.as_table();
}

template <class T, std::size_t N>
toml::array to_array(const std::array<T, N>& a) {
  toml::array out;
  for (T v : a) out.push_back(static_cast<std::conditional_t<std::is_integral_v<T>, std::int64_t, double>>(v));
  return out;
}

void write_field(toml::table& t, std::string_view name, int v) { t.insert_or_assign(name, std::int64_t(v)); }
void write_field(toml::table& t, std::string_view name, double v) { t.insert_or_assign(name, v); }
void write_field(toml::table& t, std::string_view name, std::uint64_t v) {
  t.insert_or_assign(name, static_cast<std::int64_t>(v));
}
void write_field(toml::table& t, std::string_view name, const std::string& v) { t.insert_or_assign(name, v); }
void write_field(toml::table& t, std::string_view name, char v) { t.insert_or_assign(name, std::string(1, v)); }
void write_field(toml::table& t, std::string_view name, const std::array<int, 3>& v) {
  t.insert_or_assign(name, to_array(v));
}
void write_field(toml::table& t, std::string_view name, const std::array<double, 3>& v) {
  t.insert_or_assign(name, to_array(v));
}
void write_field(toml::table& t, std::string_view name, const std::array<double, 2>& v) {
  t.insert_or_assign(name, to_array(v));
}
void write_field(toml::table& t, std::string_view name, const std::vector<std::array<double, 2>>& points) {
  toml::array out;
  for (const auto& p : points) out.push_back(toml::array{p[0], p[1]});
  t.insert_or_assign(name, std::move(out));
}
void write_field(toml::table& t, std::string_view name, const std::vector<LineParams>& lines) {
  if (lines.empty()) return;  // a scene without lines reads as one
  toml::array out;
  for (const LineParams& line : lines) {
    toml::table fields;
    visit_line_fields(line, [&](std::string_view field, auto&& value) { write_field(fields, field, value); });
    out.push_back(std::move(fields));
  }
  t.insert_or_assign(name, std::move(out));
}
void write_field(toml::table& t, std::string_view name, AutoOrNumber<const double> v) {
  if (v.value == 0.0)
    t.insert_or_assign(name, std::string("auto"));
  else
    t.insert_or_assign(name, v.value);
}

}  // namespace

const std::vector<std::string>& scene_keys() {
  static const std::vector<std::string> keys = [] {
    std::vector<std::string> k;
    const Scene scene;
    visit_scene_fields(scene, [&](std::string_view key, auto&&) { k.emplace_back(key); });
    return k;
  }();
  return keys;
}

const std::vector<std::string>& renderer_sections() {
  static const std::vector<std::string> sections = {"render", "camera", "light", "print", "output"};
  return sections;
}

SetOverride parse_set_argument(std::string_view argument) {
  std::size_t eq = argument.find('=');
  std::string shown = "--set " + std::string(argument);
  if (eq == std::string_view::npos) throw SceneError(shown + ": expected key=value");
  SetOverride o;
  o.key = trim(argument.substr(0, eq));
  o.value = trim(argument.substr(eq + 1));
  std::vector<std::string> parts = split_key(o.key);
  for (const std::string& part : parts)
    if (!is_bare_key(part))
      throw SceneError(shown + ": '" + o.key + "' is not a dotted key such as run.steps");
  if (parts.empty()) throw SceneError(shown + ": the key is empty");
  if (o.value.empty()) throw SceneError(shown + ": the value is empty");
  return o;
}

void apply_override(toml::table& document, const SetOverride& override_) {
  toml::table parsed = parse_override_value(override_);
  std::vector<std::string> parts = split_key(override_.key);
  toml::table* table = &document;
  std::string walked;
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    walked += (i ? "." : "") + parts[i];
    toml::node& child = table->emplace<toml::table>(parts[i]).first->second;
    if (!child.is_table())
      throw SceneError(override_.source() + ": '" + walked + "' is not a table");
    table = child.as_table();
  }
  table->insert_or_assign(parts.back(), std::move(*parsed.get("value")));
}

SceneFile parse_scene(std::string_view text, std::string_view source_name,
                      std::span<const SetOverride> overrides) {
  toml::table doc = parse_document(text, source_name);
  for (const SetOverride& o : overrides) apply_override(doc, o);
  check_known_keys(doc, "", all_known_keys());
  SceneFile file;
  file.scene = read_scene(doc, source_name);
  file.render_config = take_renderer_sections(doc);
  file.path = std::string(source_name);
  file.document = std::move(doc);
  return file;
}

void rethrow_located(const SceneError& e, const SceneFile& file) { rethrow_located(e, file.document, file.path); }

SceneFile load_scene_file(const std::string& path, std::span<const SetOverride> overrides) {
  std::string text;
  try {
    text = read_input_file(path, kSceneFileKind);
  } catch (const InputFileError& e) {
    throw SceneError(e.what());
  }
  return parse_scene(text, path, overrides);
}

SceneFile default_scene_file(std::span<const SetOverride> overrides) {
  SceneFile file = parse_scene("", "", overrides);
  file.path.clear();
  return file;
}

toml::table scene_to_toml(const Scene& scene) {
  toml::table root;
  visit_scene_fields(scene, [&](std::string_view key, auto&& field) {
    if (key.find('.') == std::string_view::npos)
      write_field(root, key, field);  // a top-level array of tables: [[line]]
    else
      write_field(section_of(root, key), key.substr(key.find('.') + 1), field);
  });
  return root;
}

}  // namespace papertear::io
