#include "tools/summary.hpp"

#include <cstdio>

#include "tools/output_files.hpp"
#include "tools/scene_fields.hpp"

#ifndef PAPERTEAR_VERSION
#define PAPERTEAR_VERSION "unknown"
#endif

namespace papertear::io {
namespace {

nlohmann::json field_json(char v) { return std::string(1, v); }
nlohmann::json field_json(AutoOrNumber<const double> v) {
  return v.value == 0.0 ? nlohmann::json("auto") : nlohmann::json(v.value);
}
template <class T>
nlohmann::json field_json(const T& v) {
  return v;
}
nlohmann::json field_json(const std::vector<LineParams>& lines) {
  nlohmann::json out = nlohmann::json::array();
  for (const LineParams& line : lines) {
    nlohmann::json fields = nlohmann::json::object();
    visit_line_fields(line, [&](std::string_view name, auto&& value) { fields[std::string(name)] = field_json(value); });
    out.push_back(std::move(fields));
  }
  return out;
}

}  // namespace

std::string digest_hex(std::uint64_t digest) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(digest));
  return buf;
}

nlohmann::json metrics_to_json(const Metrics& m) {
  nlohmann::json out = nlohmann::json::object();
  visit_metrics(m, [&](const char* key, const auto& value) { out[key] = value; });
  return out;
}

nlohmann::json scene_to_json(const Scene& scene) {
  nlohmann::json out = nlohmann::json::object();
  visit_scene_fields(scene, [&](std::string_view key, auto&& field) {
    std::size_t dot = key.find('.');
    if (dot == std::string_view::npos)
      out[std::string(key)] = field_json(field);  // "line": an array of objects
    else
      out[std::string(key.substr(0, dot))][std::string(key.substr(dot + 1))] = field_json(field);
  });
  return out;
}

nlohmann::json summary_json(const Scene& scene, const RunSettings& settings,
                            const RunRecord& record) {
  nlohmann::json frames = nlohmann::json::array();
  for (std::size_t i = 0; i < record.frames.size(); ++i) {
    nlohmann::json f = metrics_to_json(record.frames[i]);
    f["frame"] = i;
    frames.push_back(std::move(f));
  }
  nlohmann::json error = nullptr;
  if (record.failure)
    error = {{"kind", "blow_up"},
             {"message", record.failure->message},
             {"step", record.failure->step},
             {"node", record.failure->node}};
  return {
      {"schema", "papertear-summary"},
      {"schema_version", kSummarySchemaVersion},
      {"papertear_version", PAPERTEAR_VERSION},
      {"status", record.failure ? "blew_up" : "completed"},
      {"error", error},
      {"digest", digest_hex(record.digest)},
      {"steps", record.steps_done},
      {"steps_planned", record.steps_planned},
      {"dt", record.dt},
      {"stable_dt", settings.stable_dt},
      {"simulated_time", record.time},
      {"threads", settings.threads},
      {"wall_time_s", record.wall_seconds},
      {"step_time_s", record.step_seconds},
      {"scene_file", settings.scene_path.empty() ? nlohmann::json(nullptr)
                                                 : nlohmann::json(settings.scene_path)},
      {"scene", scene_to_json(scene)},
      {"frames", frames},
      {"final", record.frames.empty() ? nlohmann::json(nullptr)
                                      : metrics_to_json(record.frames.back())},
  };
}

void write_summary(const std::filesystem::path& dir, const Scene& scene,
                   const RunSettings& settings, const RunRecord& record) {
  // Replace rather than throw on invalid UTF-8 (a scene path, an error message): the
  // summary of a finished run is worth more than a perfectly quoted file name.
  std::string text = summary_json(scene, settings, record)
                         .dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  write_file_atomically(dir / "summary.json", text + "\n");
}

}  // namespace papertear::io
