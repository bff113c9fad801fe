// phyxel._core: the Python bindings of python/simulation.h (the package phyxel re-exports
// them; docs/python.md documents every function).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <type_traits>

#include "compute/vk_check.h"
#include "python/simulation.h"
#include "render/video_writer.h"

namespace py = pybind11;

namespace phyxel::python {
namespace {

// An (N, 3) float64 array that owns `v` (no copy: Vec3 is three packed doubles).
py::array_t<double> vec3_array(std::vector<Vec3> v) {
  static_assert(sizeof(Vec3) == 3 * sizeof(double));
  auto* owner = new std::vector<Vec3>(std::move(v));
  py::capsule free(owner, [](void* p) { delete static_cast<std::vector<Vec3>*>(p); });
  return py::array_t<double>({py::ssize_t(owner->size()), py::ssize_t(3)},
                             reinterpret_cast<const double*>(owner->data()), free);
}

template <class T>
py::array_t<T> vector_array(std::vector<T> v) {
  auto* owner = new std::vector<T>(std::move(v));
  py::capsule free(owner, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>({py::ssize_t(owner->size())}, owner->data(), free);
}

py::array_t<double> vec3(const Vec3& v) {
  py::array_t<double> a(3);
  for (int k = 0; k < 3; ++k) a.mutable_at(k) = v[k];
  return a;
}

Vec3 to_vec3(const py::object& o, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a || a.ndim() != 1 || a.size() != 3)
    throw py::value_error(std::string(what) + ": three numbers (x, y, z) expected");
  return {a.at(0), a.at(1), a.at(2)};
}

// (H, W, 3) uint8 of an RGBA frame.
py::array_t<uint8_t> rgb_array(const render::RgbaImage& image) {
  py::array_t<uint8_t> a({py::ssize_t(image.height), py::ssize_t(image.width), py::ssize_t(3)});
  uint8_t* out = a.mutable_data();
  const size_t n = size_t(image.width) * image.height;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) out[3 * i + c] = image.pixels[4 * i + c];
  return a;
}

render::RgbaImage rgba_image(const py::array_t<uint8_t, py::array::c_style>& frame) {
  if (frame.ndim() != 3 || (frame.shape(2) != 3 && frame.shape(2) != 4))
    throw py::value_error("VideoWriter.write: an (H, W, 3) or (H, W, 4) uint8 array expected");
  const auto h = uint32_t(frame.shape(0)), w = uint32_t(frame.shape(1));
  const auto channels = size_t(frame.shape(2));
  render::RgbaImage image(w, h);
  const uint8_t* in = frame.data();
  for (size_t i = 0; i < size_t(w) * h; ++i) {
    for (size_t c = 0; c < 3; ++c) image.pixels[4 * i + c] = in[channels * i + c];
    image.pixels[4 * i + 3] = channels == 4 ? in[channels * i + 3] : 255;
  }
  return image;
}

// A scene file's path, or a dict of its JSON (relative paths in it from the working folder),
// with its identity for checkpoints.
std::pair<Scene, uint64_t> scene_from(const py::object& scene) {
  if (py::isinstance<py::dict>(scene)) {
    const std::string text = py::module_::import("json").attr("dumps")(scene).cast<std::string>();
    return {parse_scene(text, "<dict>"), fnv1a64(text.data(), text.size())};
  }
  const auto file = scene.cast<std::filesystem::path>();
  Scene s = load_scene(file);
  return {std::move(s), file_hash(file)};
}

py::object json_object(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

std::unique_ptr<Simulation> make(const py::object& scene, const std::string& device, int threads,
                                 bool skip, const std::string& render_device,
                                 const std::filesystem::path& resume) {
  SimulationOptions o;
  o.device = device;
  o.threads = threads;
  o.pass_selection = skip;
  o.render_device = render_device;
  auto [s, hash] = scene_from(scene);
  return std::make_unique<Simulation>(std::move(s), hash, o, resume);
}

// Advances with Python's signals polled between advances: a Ctrl-C stops the loop after the
// current advance and raises KeyboardInterrupt, the simulation usable.
int64_t advance(Simulation& sim, int64_t steps) {
  bool interrupted = false;
  const int64_t done = sim.advance(steps, [&interrupted] {
    if (!interrupted && PyErr_CheckSignals() != 0) interrupted = true;
    return interrupted;
  });
  if (interrupted) throw py::error_already_set();
  return done;
}

// Mono: (H, W, 3); stereo: a tuple (left, right) of the two eyes' halves.
py::object render_frames(Simulation& sim, const std::string& mode, int width, int height) {
  py::array_t<uint8_t> frame = rgb_array(sim.render(mode, width, height));
  if (mode != "stereo") return frame;
  const py::slice rows(0, height, 1), left(0, width, 1), right(width, 2 * width, 1);
  return py::make_tuple(frame[py::make_tuple(rows, left)].attr("copy")(),
                        frame[py::make_tuple(rows, right)].attr("copy")());
}

// A read-only view of one of the set's arrays, which live as long as `self`.
template <class T>
py::array view(const py::object& self, const std::vector<T>& v, std::vector<py::ssize_t> shape) {
  py::array a(py::dtype::of<std::conditional_t<std::is_same_v<T, Vec3>, double, T>>(), shape,
              v.data(), self);
  a.attr("flags").attr("writeable") = false;
  return a;
}

// The tool of that name; a KeyError naming the tools there are otherwise.
size_t tool(Simulation& sim, const std::string& name) {
  try {
    return sim.tool_index(name);
  } catch (const std::out_of_range& e) {
    throw py::key_error(e.what());
  }
}

py::class_<Simulation> bind_simulation(py::module_& m) {
  py::class_<Simulation> c(m, "Simulation");
  c.def(py::init([](const py::object& scene, const std::string& device, int threads, bool skip,
                    const std::string& render_device) {
          return make(scene, device, threads, skip, render_device, {});
        }),
        py::arg("scene"), py::arg("device") = "cpu", py::arg("threads") = 0, py::arg("skip") = true,
        py::arg("render_device") = "gpu")
      .def_static(
          "resume",
          [](const py::object& scene, const std::filesystem::path& checkpoint,
             const std::string& device, int threads, bool skip, const std::string& render_device) {
            return make(scene, device, threads, skip, render_device, checkpoint);
          },
          py::arg("scene"), py::arg("checkpoint"), py::arg("device") = "cpu",
          py::arg("threads") = 0, py::arg("skip") = true, py::arg("render_device") = "gpu")
      .def("advance", &advance, py::arg("steps") = 1)
      .def_property_readonly("time", &Simulation::time)
      .def_property_readonly("steps_done", &Simulation::steps_done)
      .def_property_readonly("phyxels", [](Simulation& s) { return s.set().size(); })
      .def_property_readonly("dt", [](Simulation& s) { return s.scene().simulation.dt; })
      .def_property_readonly("substeps", [](Simulation& s) { return s.plan().substeps; })
      .def_property_readonly("at_rest", &Simulation::at_rest)
      .def_property_readonly("device", [](Simulation& s) { return s.solver().device(); })
      .def_property_readonly("tools", [](Simulation& s) {
        std::vector<std::string> names;
        for (const ToolDesc& t : s.scene().tools) names.push_back(t.name);
        return names;
      });
  return c;
}

void bind_state(py::class_<Simulation>& c) {
  c.def("positions",
        [](Simulation& s) {
          std::vector<Vec3> x = s.state(false).displacement;
          for (size_t i = 0; i < x.size(); ++i) x[i] += s.set().rest[i];
          return vec3_array(std::move(x));
        })
      .def("rest_positions",
           [](const py::object& self) {
             const PhyxelSet& set = self.cast<Simulation&>().set();
             return view(self, set.rest, {py::ssize_t(set.size()), 3});
           })
      .def("displacements", [](Simulation& s) { return vec3_array(s.state(false).displacement); })
      .def("velocities", [](Simulation& s) { return vec3_array(s.state(false).velocity); })
      .def("von_mises", [](Simulation& s) { return vector_array(s.state(true).von_mises); })
      .def("masses",
           [](const py::object& self) {
             const PhyxelSet& set = self.cast<Simulation&>().set();
             return view(self, set.mass, {py::ssize_t(set.size())});
           })
      .def("objects",
           [](const py::object& self) {
             const PhyxelSet& set = self.cast<Simulation&>().set();
             return view(self, set.object, {py::ssize_t(set.size())});
           })
      .def("flags", [](Simulation& s) { return vector_array(s.flags()); })
      .def(
          "tool_force",
          [](Simulation& s, const std::string& name) {
            return vec3(s.tool_stats(tool(s, name)).last_force);
          },
          py::arg("name"))
      .def(
          "tool_pose",
          [](Simulation& s, const std::string& name) {
            const ToolPose& p = s.tool_pose(tool(s, name));
            return py::make_tuple(vec3(p.position), vec3(p.axis));
          },
          py::arg("name"))
      .def(
          "set_tool_pose",
          [](Simulation& s, const std::string& name, const py::object& position,
             const py::object& axis) {
            const size_t k = tool(s, name);
            const Vec3 a = axis.is_none() ? s.tool_pose(k).axis : to_vec3(axis, "axis");
            s.set_tool_pose(k, to_vec3(position, "position"), a);
          },
          py::arg("name"), py::arg("position"), py::arg("axis") = py::none())
      .def("summary", [](Simulation& s) { return json_object(s.summary()); })
      .def("resection",
           [](Simulation& s) {
             const Resection r = s.resection();
             py::list inclusions;
             for (const InclusionRemoval& i : r.inclusions) {
               py::dict d;
               d["name"] = i.name;
               d["mass"] = i.mass;
               d["removed"] = i.removed;
               d["healthy_removed"] = i.healthy_removed;
               d["whole"] = i.whole;
               inclusions.append(d);
             }
             py::dict d;
             d["pieces"] = r.pieces;
             d["freed_mass"] = r.freed_mass;
             d["inclusions"] = inclusions;
             return d;
           })
      .def(
          "exposure",
          [](Simulation& s, const std::string& name) {
            try {
              return s.exposure(name);
            } catch (const std::out_of_range& e) {
              throw py::key_error(e.what());
            }
          },
          py::arg("inclusion"))
      .def("render", &render_frames, py::arg("mode") = "mono", py::arg("width") = 640,
           py::arg("height") = 480)
      .def("save_checkpoint", &Simulation::save_checkpoint, py::arg("path"))
      .def("write_points", &Simulation::write_points, py::arg("path"));
}

void bind_video(py::module_& m) {
  py::class_<render::VideoWriter>(m, "VideoWriter")
      .def(py::init(
               [](const std::filesystem::path& path, uint32_t width, uint32_t height, double fps) {
                 return std::make_unique<render::VideoWriter>(path, width, height, fps);
               }),
           py::arg("path"), py::arg("width"), py::arg("height"), py::arg("fps") = 30.0)
      .def(
          "write",
          [](render::VideoWriter& w, const py::array_t<uint8_t, py::array::c_style>& frame) {
            w.add(rgba_image(frame), w.frames());
          },
          py::arg("frame"))
      .def("close", &render::VideoWriter::finish)
      .def_property_readonly("frames", &render::VideoWriter::frames)
      .def("__enter__", [](render::VideoWriter& w) -> render::VideoWriter& { return w; })
      .def("__exit__", [](render::VideoWriter& w, py::args) { w.finish(); });
}

}  // namespace
}  // namespace phyxel::python

PYBIND11_MODULE(_core, m) {
  using namespace phyxel;
  using namespace phyxel::python;
  m.doc() = "Phyxel's simulation, driven from Python (docs/python.md)";
  py::register_exception<SceneError>(m, "SceneError", PyExc_ValueError);
  py::register_exception<CheckpointError>(m, "CheckpointError", PyExc_ValueError);
  py::register_exception<SimulationError>(m, "SimulationError", PyExc_RuntimeError);
  py::register_exception<VulkanError>(m, "VulkanError", PyExc_RuntimeError);
  m.attr("FIXED") = uint32_t(kFixed);
  m.attr("SURFACE") = uint32_t(kSurface);
  m.attr("REMOVED") = uint32_t(kRemoved);
  m.attr("CONTACT") = kContactFlag;
  py::class_<Simulation> c = bind_simulation(m);
  bind_state(c);
  bind_video(m);
}
