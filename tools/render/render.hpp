// The renderer and mesh export in one include, for the command-line tool and embedders.
//
//   auto settings = papertear::render::parse_render_settings(scene_toml, scene_dir);
//   papertear::render::Renderer renderer(settings);
//   const auto camera = renderer.camera_for(sim.world());        // once, for a steady view
//   ...
//   papertear::render::write_png("frame_0001.png", renderer.draw(sim.world(), camera));
//   const auto mesh = papertear::render::build_surface_mesh(sim.world(), renderer.mesh_options());
//   papertear::render::export_glb(mesh, "frame_0001.glb", {.print = &renderer.print()});
#pragma once
#include "tools/render/camera.hpp"
#include "tools/render/frame_sinks.hpp"
#include "tools/render/image.hpp"
#include "tools/render/mesh_export.hpp"
#include "tools/render/print.hpp"
#include "tools/render/raytracer.hpp"
#include "tools/render/settings.hpp"
#include "tools/render/surface.hpp"
