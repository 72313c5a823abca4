"""Blender client test: blender -b --python-exit-code 1 --python blender_check.py -- RUN_DIR

Imports RUN_DIR/animation.glb with tools/blender/import_papertear.py, plays it to its first
and last frames and checks the evaluated sheet against those frames' own .glb files
(RUN_DIR/mesh/, written with output.mesh_frames = "all") within 1e-4 of the sheet's size;
then imports the last frame's .glb alone. Raises (exit 1) on any mismatch.
"""
import os
import sys

import numpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "tools", "blender"))
import import_papertear  # noqa: E402  (sets the numpy shim before the importer loads)
import bpy  # noqa: E402
from glb_read import Glb, gltf_to_blender  # noqa: E402


def evaluated_points(obj):
    dg = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(dg)
    mesh = ev.to_mesh()
    co = numpy.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    ev.to_mesh_clear()
    co = co.reshape(-1, 3)
    m = numpy.array(obj.matrix_world)
    return co @ m[:3, :3].T + m[:3, 3]


def int_attribute(obj, name):
    values = numpy.empty(len(obj.data.vertices), dtype=numpy.int32)
    obj.data.attributes[name].data.foreach_get("value", values)
    return values


def nearest(points_by_orig, o, p):
    candidates = points_by_orig.get(int(o))
    if candidates is None:
        return None
    return float(numpy.min(numpy.max(numpy.abs(numpy.array(candidates) - p), axis=1)))


def by_original(points, originals):
    out = {}
    for p, o in zip(points, originals):
        out.setdefault(int(o), []).append(p)
    return out


def check_frame(obj, frame_file, scene_frame, tol):
    """The sheet as played equals the frame's own mesh: each vertex of that mesh has a played
    vertex on it (same original node), and each played vertex at an original node on that
    frame's surface lies on it. Played vertices at other original nodes are those of cracks
    still closed, inside the sheet (animation.hpp)."""
    bpy.context.scene.frame_set(scene_frame)
    got = evaluated_points(obj)
    orig = int_attribute(obj, "original_node")
    want_p, _, want_orig = Glb(frame_file).sheet()
    want_p = gltf_to_blender(want_p)
    own, played = by_original(want_p, want_orig), by_original(got, orig)
    off = [nearest(own, o, p) for p, o in zip(got, orig)]
    on_surface = [d for d in off if d is not None]
    missing = [nearest(played, o, p) for p, o in zip(want_p, want_orig)]
    worst = max(on_surface + [d if d is not None else numpy.inf for d in missing])
    print(f"blender_check: frame {scene_frame} vs {os.path.basename(frame_file)}: {len(got)} vertices, "
          f"{len(on_surface)} on its surface, worst {worst:.3g} m (tolerance {tol:.3g} m)")
    if worst > tol:
        raise RuntimeError(f"frame {scene_frame} is off its own mesh by {worst} m")
    return len(on_surface)


def main():
    run = sys.argv[sys.argv.index("--") + 1]
    frames = sorted(f for f in os.listdir(os.path.join(run, "mesh")) if f.endswith(".glb"))
    sheet = import_papertear.import_run(run)
    scene = bpy.context.scene
    fps = Glb(os.path.join(run, "animation.glb")).json["asset"]["extras"]["fps"]
    if scene.render.fps != fps:
        raise RuntimeError(f"scene fps {scene.render.fps}, file {fps}")
    if scene.frame_end - scene.frame_start + 1 != len(frames):
        raise RuntimeError(f"frame range {scene.frame_start}..{scene.frame_end} for {len(frames)} frames")
    last_p = gltf_to_blender(Glb(os.path.join(run, "mesh", frames[-1])).sheet()[0])
    size = float(numpy.max(last_p.max(axis=0) - last_p.min(axis=0)))
    check_frame(sheet, os.path.join(run, "mesh", frames[0]), scene.frame_start, 1e-4 * size)
    if check_frame(sheet, os.path.join(run, "mesh", frames[-1]), scene.frame_end, 1e-4 * size) != len(
            sheet.data.vertices):
        raise RuntimeError("at the last frame every vertex must be on the frame's own surface")
    # The ids came back as integers, node for node the final topology's.
    _, last_nodes, _ = Glb(os.path.join(run, "mesh", frames[-1])).sheet()
    if set(int_attribute(sheet, "node").tolist()) != set(last_nodes.tolist()):
        raise RuntimeError("node ids of the animated sheet differ from the last frame's")
    animated_vertices = len(sheet.data.vertices)
    # One frame's mesh imports on its own too.
    bpy.ops.wm.read_factory_settings(use_empty=True)
    single = import_papertear.import_run(os.path.join(run, "mesh", frames[-1]))
    if len(single.data.vertices) == 0 or "node" not in single.data.attributes:
        raise RuntimeError("the last frame's .glb imported without vertices or ids")
    print(f"blender_check: ok ({len(frames)} frames, {animated_vertices} vertices, "
          f"single frame {len(single.data.vertices)} vertices)")


main()
