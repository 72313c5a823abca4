// The results of a sweep: one row per point, stored as DIR/points/point_NNNNN.json as soon as
// the point is done, then merged into DIR/sweep.csv and DIR/sweep.json. A whole sweep and a
// sweep spread over machines (--index) both end in collect_sweep, which reads the point files
// back, so their tables are the same bytes.
//
// A row is an ordered JSON object: index, seed, the swept keys' values in the resolved scene,
// status ("completed", "blew_up", "error"), error, digest, then the final metrics of the
// summary (tools/summary.cpp) and peak_grip_force, the largest grip force of any frame. Wall
// times are kept out of the rows (they are in the point files), so rows depend only on the
// sweep definition.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/run_frames.hpp"
#include "tools/sweep_file.hpp"

namespace papertear::io {

inline constexpr int kSweepSchemaVersion = 1;

using Row = nlohmann::ordered_json;

// The row of a point that ran (or blew up): `record` is its run.
Row point_row(const SweepDefinition& sweep, const SweepPoint& point, const Scene& scene,
              const RunRecord& record);
// The row of a point that could not run at all (e.g. run.dt above the stable limit).
Row failed_row(const SweepDefinition& sweep, const SweepPoint& point, const Scene& scene,
               const std::string& error);
bool row_completed(const Row& row);

// DIR/points/point_NNNNN.json.
std::filesystem::path point_file(const std::filesystem::path& dir, int index);

// Writes the point file atomically, with the sweep's hash and point count. Throws OutputError.
void write_point_file(const std::filesystem::path& dir, std::uint64_t sweep_hash, int count,
                      const Row& row, double wall_seconds, int threads);

// Reads every point file of the sweep, in index order. Throws SceneError naming the missing
// points, or a file that is malformed or belongs to another sweep (another hash or count).
std::vector<Row> read_point_files(const std::filesystem::path& dir, std::uint64_t sweep_hash, int count);

// The table as CSV (a header, then one line per row; columns in order of first appearance)
// and as JSON (the rows with the sweep's hash and keys).
std::string rows_csv(const std::vector<Row>& rows);
std::string rows_json(const SweepDefinition& sweep, std::uint64_t sweep_hash, const std::vector<Row>& rows);

}  // namespace papertear::io
