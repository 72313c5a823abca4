#include "tools/toml_keys.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace papertear::io {
namespace {

// Longer than any scene key (the longest is about 30 characters).
constexpr std::size_t kMaxKeyLength = 128;

std::vector<std::string_view> split_dots(std::string_view key) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    std::size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) return parts;
    start = dot + 1;
  }
}

std::string join(std::span<const std::string_view> parts) {
  std::string out;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (i) out += '.';
    out += parts[i];
  }
  return out;
}

// How many typos a name of this length may carry and still be recognised.
std::size_t typo_budget(std::size_t length) { return std::max<std::size_t>(1, length / 3); }

struct Candidate {
  std::string key;
  std::size_t distance = std::numeric_limits<std::size_t>::max();
};

// Compares the first components of `key` with every known key and every section above one,
// keeping the rest of `key` as typed: catches typos in a section name.
Candidate nearest_by_prefix(std::string_view key, std::span<const std::string> known) {
  auto typed = split_dots(key);
  Candidate best;
  for (const std::string& k : known) {
    auto parts = split_dots(k);
    for (std::size_t n = 1; n <= std::min(parts.size(), typed.size()); ++n) {
      std::string head = join(std::span(typed).first(n));
      std::string section = join(std::span(parts).first(n));
      std::size_t d = edit_distance(head, section);
      if (d == 0 || d > typo_budget(head.size()) || d >= best.distance) continue;
      std::string guess = section;
      for (std::size_t i = n; i < typed.size(); ++i) guess += "." + std::string(typed[i]);
      best = {guess, d};
    }
  }
  return best;
}

// The value as written, for scalars only (arrays and tables would make the message long).
std::string quoted_value(const toml::node& node) {
  std::ostringstream out;
  if (auto s = node.as_string()) {
    out << '"' << s->get() << '"';
  } else if (node.is_number() || node.is_boolean()) {
    node.visit([&](const auto& v) {
      if constexpr (toml::is_value<decltype(v)>) out << v;
    });
  }
  return out.str();
}

bool starts_with_section(std::string_view key, std::string_view section) {
  return key.size() > section.size() && key.starts_with(section) && key[section.size()] == '.';
}

std::string section_list(std::span<const std::string> known) {
  std::vector<std::string> sections;
  for (const std::string& k : known) {
    std::string first(split_dots(k).front());
    if (std::find(sections.begin(), sections.end(), first) == sections.end())
      sections.push_back(first);
  }
  std::string out;
  for (const std::string& s : sections) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

std::size_t edit_distance(std::string_view a, std::string_view b) {
  // Three rolling rows of the dynamic programme: the swap rule looks two rows back.
  std::vector<std::size_t> two(b.size() + 1), one(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) one[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      cur[j] = std::min({one[j] + 1, cur[j - 1] + 1, one[j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        cur[j] = std::min(cur[j], two[j - 2] + 1);
    }
    std::swap(two, one);
    std::swap(one, cur);
  }
  return one[b.size()];
}

std::optional<std::string> nearest_key(std::string_view key, std::span<const std::string> known) {
  Candidate whole;
  for (const std::string& k : known) {
    std::size_t d = edit_distance(key, k);
    if (d > 0 && d <= typo_budget(key.size()) && d < whole.distance) whole = {k, d};
  }
  if (!whole.key.empty()) return whole.key;
  if (Candidate prefix = nearest_by_prefix(key, known); !prefix.key.empty()) return prefix.key;
  std::string_view last = split_dots(key).back();
  for (const std::string& k : known)
    if (split_dots(k).back() == last && k != key) return k;
  return std::nullopt;
}

std::string where(const toml::node& node) {
  const toml::source_region& src = node.source();
  if (!src.path) return {};
  const std::string& path = *src.path;
  if (path.starts_with("--")) return path;  // a command-line argument, e.g. "--set k=v"
  if (!src.begin) return path;
  return path + ":" + std::to_string(src.begin.line) + ":" + std::to_string(src.begin.column);
}

void fail_at(const toml::node& node, std::string_view key, std::string_view problem) {
  std::string place = where(node);
  std::string message = place.empty() ? "" : place + ": ";
  if (!key.empty()) message += std::string(key) + ": ";
  message += problem;
  throw SceneError(message);
}

std::string type_phrase(const toml::node& node) {
  std::string value = quoted_value(node);
  std::string suffix = value.empty() ? "" : " (" + value + ")";
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string" + suffix;
    case toml::node_type::integer: return "an integer" + suffix;
    case toml::node_type::floating_point: return "a floating-point number" + suffix;
    case toml::node_type::boolean: return "a boolean" + suffix;
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

void check_known_keys(const toml::table& table, std::string_view prefix,
                      std::span<const std::string> known) {
  for (const auto& [k, node] : table) {
    // No key is this long: name it by its start, and spare the edit distances (quadratic).
    if (k.str().size() > kMaxKeyLength)
      fail_at(node, "", "unknown key of " + std::to_string(k.str().size()) + " characters ('" +
                            std::string(k.str().substr(0, 32)) + "...')");
    std::string dotted = prefix.empty() ? std::string(k.str())
                                        : std::string(prefix) + "." + std::string(k.str());
    if (std::find(known.begin(), known.end(), dotted) != known.end()) continue;
    bool has_children = std::any_of(known.begin(), known.end(), [&](const std::string& kk) {
      return starts_with_section(kk, dotted);
    });
    if (has_children) {
      if (!node.is_table()) fail_at(node, dotted, "expected a table, got " + type_phrase(node));
      check_known_keys(*node.as_table(), dotted, known);
      continue;
    }
    // Name the first value under an unknown table: "rnu.steps" locates the mistake and
    // finds "run.steps", where "rnu" alone would only find the section.
    const toml::node* leaf = &node;
    while (leaf->is_table() && !leaf->as_table()->empty()) {
      auto first = leaf->as_table()->begin();
      dotted += "." + std::string(first->first.str());
      leaf = &first->second;
    }
    std::string problem = "unknown key '" + dotted + "'";
    if (auto guess = nearest_key(dotted, known))
      problem += " (did you mean '" + *guess + "'?)";
    else if (prefix.empty())
      problem += " (sections are: " + section_list(known) + ")";
    fail_at(*leaf, "", problem);
  }
}

double read_number(const toml::node& node, std::string_view key) {
  if (auto i = node.as_integer()) return static_cast<double>(i->get());
  auto f = node.as_floating_point();
  if (!f) fail_at(node, key, "expected a number, got " + type_phrase(node));
  if (!std::isfinite(f->get())) fail_at(node, key, "must be a finite number, got " + quoted_value(node));
  return f->get();
}

std::int64_t read_integer(const toml::node& node, std::string_view key) {
  auto i = node.as_integer();
  if (!i) fail_at(node, key, "expected an integer, got " + type_phrase(node));
  return i->get();
}

int read_int(const toml::node& node, std::string_view key) {
  std::int64_t v = read_integer(node, key);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail_at(node, key, "integer " + std::to_string(v) + " is out of range");
  return static_cast<int>(v);
}

std::uint64_t read_unsigned(const toml::node& node, std::string_view key) {
  std::int64_t v = read_integer(node, key);
  if (v < 0) fail_at(node, key, "must not be negative, got " + std::to_string(v));
  return static_cast<std::uint64_t>(v);
}

bool read_bool(const toml::node& node, std::string_view key) {
  auto b = node.as_boolean();
  if (!b) fail_at(node, key, "expected true or false, got " + type_phrase(node));
  return b->get();
}

std::string read_string(const toml::node& node, std::string_view key) {
  auto s = node.as_string();
  if (!s) fail_at(node, key, "expected a string, got " + type_phrase(node));
  return s->get();
}

char read_letter(const toml::node& node, std::string_view key) {
  std::string s = read_string(node, key);
  if (s.size() != 1)
    fail_at(node, key, "expected a one-letter string such as \"x\", got \"" + s + "\"");
  return s[0];
}

namespace {
template <class T, std::size_t N, class Read>
std::array<T, N> read_tuple(const toml::node& node, std::string_view key, const char* what, Read read) {
  auto arr = node.as_array();
  if (!arr || arr->size() != N)
    fail_at(node, key, "expected an array of " + std::to_string(N) + " " + what + ", got " +
                           (arr ? "an array of " + std::to_string(arr->size()) : type_phrase(node)));
  std::array<T, N> out{};
  for (std::size_t i = 0; i < N; ++i)
    out[i] = read((*arr)[i], std::string(key) + "[" + std::to_string(i) + "]");
  return out;
}
double read_number_at(const toml::node& n, const std::string& k) { return read_number(n, k); }
}  // namespace

std::array<double, 2> read_number2(const toml::node& node, std::string_view key) {
  return read_tuple<double, 2>(node, key, "numbers", read_number_at);
}

std::array<double, 3> read_number3(const toml::node& node, std::string_view key) {
  return read_tuple<double, 3>(node, key, "numbers", read_number_at);
}

std::array<int, 3> read_int3(const toml::node& node, std::string_view key) {
  return read_tuple<int, 3>(node, key, "integers", [](const toml::node& n, const std::string& k) {
    return read_int(n, k);
  });
}

const toml::table* find_table(const toml::table& parent, std::string_view key,
                              std::string_view dotted_name) {
  const toml::node* node = parent.get(key);
  if (!node) return nullptr;
  if (!node->is_table()) fail_at(*node, dotted_name, "expected a table, got " + type_phrase(*node));
  return node->as_table();
}

}  // namespace papertear::io
