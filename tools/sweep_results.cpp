#include "tools/sweep_results.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

#include "core/input_file.hpp"
#include "tools/output_files.hpp"
#include "tools/summary.hpp"

#ifndef PAPERTEAR_VERSION
#define PAPERTEAR_VERSION "unknown"
#endif

namespace papertear::io {
namespace {

constexpr const char* kPointSchema = "papertear-sweep-point";
// The metric columns in reading order (metrics_to_json sorts its keys).
constexpr std::array<const char*, 13> kMetricOrder = {
    "splits_inplane", "splits_interlayer", "pieces", "torn_edge_length", "edge_roughness",
    "separation_roughness", "peeled_area", "grip_force", "peak_grip_force", "kinetic_energy", "elastic_energy",
    "intact_blocks", "time"};
// Missing point files named in an error before "and N more".
constexpr std::size_t kNamedMissing = 10;

Row to_row(const nlohmann::json& j) { return Row::parse(j.dump()); }

// index, seed and the swept keys' values as the resolved scene has them.
Row row_head(const SweepDefinition& sweep, const SweepPoint& point, const Scene& scene) {
  Row row;
  row["index"] = point.index;
  row["seed"] = scene.run.seed;
  const nlohmann::json values = scene_to_json(scene);
  for (const std::string& key : sweep.keys) {
    const std::size_t dot = key.find('.');
    row[key] = to_row(values.at(key.substr(0, dot)).at(key.substr(dot + 1)));
  }
  return row;
}

double peak_grip_force(const std::vector<Metrics>& frames) {
  double peak = frames.front().grip_force;
  for (const Metrics& m : frames) peak = std::max(peak, m.grip_force);
  return peak;
}

// The edge roughness of the first frame in which the sheet is in two or more pieces: the
// tear as it was when it came apart. Fast cracks keep branching after that and the pieces
// fragment, which makes the final roughness depend on which two pieces are largest at the
// end; this one is the tear itself. 0 when the sheet never came apart.
double separation_roughness(const std::vector<Metrics>& frames) {
  for (const Metrics& m : frames)
    if (m.pieces >= 2) return m.edge_roughness;
  return 0.0;
}

std::string hash_hex(std::uint64_t h) { return digest_hex(h); }

std::string file_text(const std::filesystem::path& path) { return read_input_file(path.string(), kPointResultKind); }

std::string missing_message(const std::filesystem::path& dir, const std::vector<int>& missing, int count) {
  std::string names, indices;
  for (std::size_t i = 0; i < missing.size() && i < kNamedMissing; ++i) {
    names += (i ? ", " : "") + point_file(dir, missing[i]).filename().string();
    indices += (i ? " " : "") + std::to_string(missing[i]);
  }
  std::string message = (dir / "points").string() + ": " + std::to_string(missing.size()) + " of " +
                        std::to_string(count) + " point files are missing: " + names;
  if (missing.size() > kNamedMissing)
    message += " and " + std::to_string(missing.size() - kNamedMissing) + " more";
  return message + " (run them with --index: " + indices + (missing.size() > kNamedMissing ? " ..." : "") + ")";
}

Row read_point(const std::filesystem::path& path, std::uint64_t sweep_hash, int count, int index) {
  Row j;
  try {
    j = Row::parse(file_text(path));
  } catch (const nlohmann::json::parse_error& e) {
    throw SceneError(path.string() + ": not a sweep point file (" + e.what() + ")");
  }
  if (!j.is_object() || j.value("schema", "") != kPointSchema || !j.contains("row"))
    throw SceneError(path.string() + ": not a sweep point file");
  const std::string hash = j.value("sweep_hash", "");
  if (hash != hash_hex(sweep_hash) || j.value("count", -1) != count)
    throw SceneError(path.string() + ": belongs to another sweep (its sweep hash is " + hash + ", " +
                     std::to_string(j.value("count", -1)) + " points; this sweep's is " +
                     hash_hex(sweep_hash) + ", " + std::to_string(count) +
                     " points): the sweep file or its base scene changed since it was written");
  if (j.value("index", -1) != index || j["row"].value("index", -1) != index)
    throw SceneError(path.string() + ": holds point " + std::to_string(j.value("index", -1)) +
                     ", expected point " + std::to_string(index));
  return j["row"];
}

// --- CSV --------------------------------------------------------------------------------

std::string csv_field(const Row& v) {
  if (v.is_null()) return "";
  std::string s = v.is_string() ? v.get<std::string>() : v.dump();
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::vector<std::string> columns(const std::vector<Row>& rows) {
  std::vector<std::string> out;
  for (const Row& row : rows)
    for (const auto& [key, value] : row.items())
      if (std::find(out.begin(), out.end(), key) == out.end()) out.push_back(key);
  return out;
}

}  // namespace

Row point_row(const SweepDefinition& sweep, const SweepPoint& point, const Scene& scene,
              const RunRecord& record) {
  Row row = row_head(sweep, point, scene);
  row["status"] = record.failure ? "blew_up" : "completed";
  row["error"] = record.failure ? Row("step " + std::to_string(record.failure->step) + ", node " +
                                     std::to_string(record.failure->node) + ": " + record.failure->message)
                                : Row(nullptr);
  row["digest"] = digest_hex(record.digest);
  row["steps"] = record.steps_done;
  if (record.frames.empty()) return row;
  Row metrics = to_row(metrics_to_json(record.frames.back()));
  metrics.erase("step");  // the steps column says it
  metrics["peak_grip_force"] = peak_grip_force(record.frames);
  metrics["separation_roughness"] = separation_roughness(record.frames);
  for (const char* key : kMetricOrder)
    if (metrics.contains(key)) {
      row[key] = metrics[key];
      metrics.erase(key);
    }
  for (const auto& [key, value] : metrics.items()) row[key] = value;  // metrics added later
  return row;
}

Row failed_row(const SweepDefinition& sweep, const SweepPoint& point, const Scene& scene,
               const std::string& error) {
  Row row = row_head(sweep, point, scene);
  row["status"] = "error";
  row["error"] = error;
  return row;
}

bool row_completed(const Row& row) { return row.value("status", "") == "completed"; }

std::filesystem::path point_file(const std::filesystem::path& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "point_%05d.json", index);
  return dir / "points" / name;
}

void write_point_file(const std::filesystem::path& dir, std::uint64_t sweep_hash, int count,
                      const Row& row, double wall_seconds, int threads) {
  const int index = row.at("index").get<int>();
  Row j;
  j["schema"] = kPointSchema;
  j["schema_version"] = kSweepSchemaVersion;
  j["papertear_version"] = PAPERTEAR_VERSION;
  j["sweep_hash"] = hash_hex(sweep_hash);
  j["count"] = count;
  j["index"] = index;
  j["threads"] = threads;
  j["wall_time_s"] = wall_seconds;
  j["row"] = row;
  create_output_dir(dir / "points");
  write_file_atomically(point_file(dir, index),
                        j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
}

std::vector<Row> read_point_files(const std::filesystem::path& dir, std::uint64_t sweep_hash, int count) {
  std::vector<int> missing;
  for (int i = 0; i < count; ++i)
    if (!std::filesystem::is_regular_file(point_file(dir, i))) missing.push_back(i);
  if (!missing.empty()) throw SceneError(missing_message(dir, missing, count));
  std::vector<Row> rows;
  for (int i = 0; i < count; ++i) rows.push_back(read_point(point_file(dir, i), sweep_hash, count, i));
  return rows;
}

std::string rows_csv(const std::vector<Row>& rows) {
  const std::vector<std::string> cols = columns(rows);
  std::string out;
  for (std::size_t c = 0; c < cols.size(); ++c) out += (c ? "," : "") + csv_field(Row(cols[c]));
  out += "\n";
  for (const Row& row : rows) {
    for (std::size_t c = 0; c < cols.size(); ++c)
      out += (c ? "," : "") + (row.contains(cols[c]) ? csv_field(row[cols[c]]) : std::string());
    out += "\n";
  }
  return out;
}

std::string rows_json(const SweepDefinition& sweep, std::uint64_t sweep_hash, const std::vector<Row>& rows) {
  Row j;
  j["schema"] = "papertear-sweep";
  j["schema_version"] = kSweepSchemaVersion;
  j["sweep_hash"] = hash_hex(sweep_hash);
  j["count"] = rows.size();
  j["keys"] = sweep.keys;
  j["seeded"] = sweep.seeded;
  j["completed"] = std::count_if(rows.begin(), rows.end(), row_completed);
  j["rows"] = rows;
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace papertear::io
