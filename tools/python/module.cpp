// The Python module `papertear`: a Simulation built from a scene and --set style overrides
// exactly as `papertear run` builds it (tools/scene_setup.hpp), numpy views of the solver's
// columns, the summary as a dict and checkpoints. Errors carry the CLI's one-line message.
//
// Why positions is a copy while x, y, z are views: the solver keeps each coordinate in its
// own allocation, deliberately staggered against 4 KiB aliasing (core/aligned_array.hpp), so
// no single (nodes, 3) array with constant strides can describe them. A view per column is
// the zero-copy form; `positions` gathers the three into one (nodes, 3) array.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "core/checkpoint.hpp"
#include "fracture/metrics.hpp"
#include "tools/python/embedded_run.hpp"
#include "tools/summary.hpp"

namespace py = pybind11;
using papertear::embed::EmbeddedRun;

namespace {

// A Python override value as the text one would type after --set key=.
std::string toml_text(const py::handle& value, const std::string& key, bool nested);

std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}

std::string list_text(const py::handle& value, const std::string& key) {
  std::string out = "[";
  bool first = true;
  for (const py::handle item : value) {
    out += (first ? "" : ", ") + toml_text(item, key, true);
    first = false;
  }
  return out + "]";
}

std::string toml_text(const py::handle& value, const std::string& key, bool nested) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(value)) return py::str(value).cast<std::string>();
  if (py::isinstance<py::float_>(value)) {
    const double d = value.cast<double>();
    if (std::isnan(d)) return "nan";
    if (std::isinf(d)) return d > 0 ? "inf" : "-inf";
    return py::repr(value).cast<std::string>();  // shortest round trip, always with . or e
  }
  // A string on its own is taken as typed, like --set (washi, auto, 1.5); inside an array it
  // must be a TOML string.
  if (py::isinstance<py::str>(value)) return nested ? quoted(value.cast<std::string>()) : value.cast<std::string>();
  if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) return list_text(value, key);
  throw py::value_error("overrides: " + key + ": a value must be a number, bool, string or list, got " +
                        py::str(py::type::of(value).attr("__name__")).cast<std::string>());
}

std::vector<papertear::io::SetOverride> parse_overrides(const py::object& overrides) {
  std::vector<papertear::io::SetOverride> out;
  if (overrides.is_none()) return out;
  if (!py::isinstance<py::dict>(overrides))
    throw py::type_error("overrides must be a dict of dotted keys to values, e.g. {\"sheet.cells\": [30, 20, 3]}");
  for (const auto& [k, v] : overrides.cast<py::dict>()) {
    if (!py::isinstance<py::str>(k)) throw py::type_error("overrides: keys must be strings");
    const std::string key = k.cast<std::string>();
    out.push_back(papertear::io::parse_set_argument(key + "=" + toml_text(v, key, false)));
  }
  return out;
}

// Python's json module turns summary_json's text into the same dict that json.load gives
// for summary.json, so the two cannot drift apart.
py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

// A read-only numpy view of `count` elements at `data`, keeping `owner` (the Python
// Simulation) alive. Read-only: the solver's state changes only by stepping.
template <class T>
py::array view(const T* data, std::vector<py::ssize_t> shape, const py::object& owner) {
  py::array_t<T> a(shape, {}, data, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array column(const EmbeddedRun& run, std::span<const float> papertear::NodeView::*member, const py::object& owner) {
  const papertear::NodeView n = run.simulation().nodes();
  return view((n.*member).data(), {py::ssize_t(n.count)}, owner);
}

py::array gather3(std::span<const float> a, std::span<const float> b, std::span<const float> c) {
  py::array_t<float> out({py::ssize_t(a.size()), py::ssize_t(3)});
  auto m = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < a.size(); ++i) {
    m(py::ssize_t(i), 0) = a[i];
    m(py::ssize_t(i), 1) = b[i];
    m(py::ssize_t(i), 2) = c[i];
  }
  return out;
}

py::array cell_nodes(const EmbeddedRun& run, const py::object& owner) {
  const papertear::TopologyView t = run.simulation().topology();
  return view(t.cell_nodes.data(), {py::ssize_t(t.cell_nodes.size() / 8), py::ssize_t(8)}, owner);
}

py::dict pieces(const EmbeddedRun& run) {
  const papertear::Metrics m = papertear::measure(run.simulation().world());
  py::dict d;
  d["count"] = m.pieces;
  d["cells"] = m.piece_cells;
  d["fragments"] = m.fragments;
  return d;
}

void register_errors(py::module_& m) {
  static py::exception<papertear::SceneError> scene_error(m, "SceneError", PyExc_ValueError);
  static py::exception<papertear::CheckpointError> checkpoint_error(m, "CheckpointError", PyExc_ValueError);
  static py::exception<papertear::BlowUpError> blow_up(m, "BlowUpError", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const papertear::SceneError& e) {
      scene_error(e.what());
    } catch (const papertear::CheckpointError& e) {
      checkpoint_error(e.what());
    } catch (const papertear::BlowUpError& e) {
      blow_up(e.what());
    }
  });
}

}  // namespace

namespace {

std::unique_ptr<EmbeddedRun> make_run(const py::object& scene, const py::object& overrides, int threads) {
  if (threads < 0) throw py::value_error("threads must be 0 (all hardware threads) or more");
  std::string path;
  if (!scene.is_none()) path = py::str(py::module_::import("os").attr("fspath")(scene)).cast<std::string>();
  std::vector<papertear::io::SetOverride> sets = parse_overrides(overrides);
  py::gil_scoped_release release;  // building a large lattice takes a while
  return std::make_unique<EmbeddedRun>(path, sets, threads);
}

void step(EmbeddedRun& run, int n) {
  if (n < 0) throw py::value_error("step: n must be 0 or more, got " + std::to_string(n));
  py::gil_scoped_release release;  // other Python threads run while the solver steps
  run.step(n);
}

void bind_state(py::class_<EmbeddedRun>& c) {
  using NV = papertear::NodeView;
  c.def_property_readonly("positions", [](const EmbeddedRun& r) {
     const NV n = r.simulation().nodes();
     return gather3(n.px, n.py, n.pz);
   }, "(nodes, 3) float32 array of node positions (mm): a copy gathered from x, y, z")
   .def_property_readonly("velocities", [](const EmbeddedRun& r) {
     const NV n = r.simulation().nodes();
     return gather3(n.vx, n.vy, n.vz);
   }, "(nodes, 3) float32 array of node velocities: a copy gathered from vx, vy, vz")
   .def_property_readonly("x", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::px, self); },
                          "read-only view of the solver's x column (nodes,); valid until the next step()")
   .def_property_readonly("y", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::py, self); })
   .def_property_readonly("z", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::pz, self); })
   .def_property_readonly("vx", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::vx, self); })
   .def_property_readonly("vy", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::vy, self); })
   .def_property_readonly("vz", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::vz, self); })
   .def_property_readonly("masses", [](py::object self) { return column(self.cast<const EmbeddedRun&>(), &NV::mass, self); })
   .def_property_readonly("cell_nodes", [](py::object self) { return cell_nodes(self.cast<const EmbeddedRun&>(), self); },
                          "read-only view (cells, 8) uint32: each cell's node at corner q = dx | dy<<1 | dz<<2")
   .def_property_readonly("cells", [](const EmbeddedRun& r) {
     const auto& d = r.simulation().topology().dims;
     return py::make_tuple(d.nx, d.ny, d.nl);
   }, "the lattice's cell counts (nx, ny, nz)")
   .def_property_readonly("node_count", [](const EmbeddedRun& r) { return r.simulation().nodes().count; });
}

void bind_run(py::class_<EmbeddedRun>& c) {
  c.def("step", &step, py::arg("n") = 1, "advance n steps; releases the GIL while stepping")
   .def("digest", [](const EmbeddedRun& r) { return papertear::io::digest_hex(r.simulation().digest()); },
        "16 hex digits, the same as `papertear run` prints for this scene and step count")
   .def("summary", [](const EmbeddedRun& r) { return to_python(r.summary()); },
        "summary.json's layout as a dict; each step() call is one frame")
   .def("metrics", [](const EmbeddedRun& r) {
     return to_python(papertear::io::metrics_to_json(papertear::measure(r.simulation().world())));
   }, "the metrics of the current state as a dict")
   .def("pieces", &pieces, "the connected pieces: count, cells per piece (largest first), fragments")
   .def("scene", [](const EmbeddedRun& r) { return to_python(papertear::io::scene_to_json(r.simulation().scene())); },
        "every scene key, resolved, as a dict")
   .def("save_checkpoint", [](const EmbeddedRun& r, const py::object& path) {
     const std::string p = py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
     py::gil_scoped_release release;
     r.save_checkpoint(p);
   }, py::arg("path"), "write a checkpoint that load_checkpoint() and `papertear resume` read")
   .def_static("load_checkpoint", [](const py::object& path, int threads) {
     if (threads < 0) throw py::value_error("threads must be 0 (all hardware threads) or more");
     const std::string p = py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
     py::gil_scoped_release release;
     return EmbeddedRun::from_checkpoint(p, threads);
   }, py::arg("path"), py::arg("threads") = 0, "a Simulation continuing a checkpoint file")
   .def_property_readonly("steps_done", [](const EmbeddedRun& r) { return r.simulation().steps_done(); })
   .def_property_readonly("time", [](const EmbeddedRun& r) { return r.simulation().time(); })
   .def_property_readonly("dt", [](const EmbeddedRun& r) { return r.simulation().dt(); })
   .def_property_readonly("threads", &EmbeddedRun::threads);
}

}  // namespace

PYBIND11_MODULE(papertear, m) {
  m.doc() = "papertear: paper tearing for computer graphics (mass-spring lattice, node splitting)";
  m.attr("__version__") = PAPERTEAR_VERSION;
  register_errors(m);
  py::class_<EmbeddedRun> sim(m, "Simulation", "a simulation built from a scene, as `papertear run` builds it");
  sim.def(py::init(&make_run), py::arg("scene") = py::none(), py::arg("overrides") = py::none(),
          py::arg("threads") = 0,
          "scene: a TOML file or None for the built-in default; overrides: {dotted key: value} like --set");
  bind_state(sim);
  bind_run(sim);
}
