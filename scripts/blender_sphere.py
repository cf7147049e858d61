"""Render a unit sphere with a material script of `halfback fit --emit blender` in Blender's Cycles,
in the scene of `halfback render` (docs/render.md, "Scene and camera"), and save the linear image
as a NumPy .npy array (H, W, 3), row 0 at the top.

Run by Blender: blender -b --factory-startup --python scripts/blender_sphere.py -- \
    MATERIAL.py ENV OUT.npy SIZE SPP
ENV: a latitude-longitude .hdr/.exr file or constant:V.

halfback's frame is +y up, the camera on +z looking along -z, +x to the right; its map's centre
is -z and its right half +x. Blender's equirectangular lookup puts the map's centre at +X, its
right half at -Y and the top at +Z, so halfback's (x, y, z) is Blender's (-Y, Z, -X): the camera
sits on -X looking along +X with +Z up and -Y to its right, and the map needs no rotation
(checked on a mirror sphere: every pixel is the map's texel in the mirror direction).
"""
import os
import sys

import bpy
import numpy as np
from mathutils import Matrix


def build_scene(material_script, env, size, spp):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = spp
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.max_bounces = 0  # direct light only, as halfback's renderer (a convex sphere)
    scene.cycles.filter_width = 0.01  # a box pixel, as halfback's
    scene.cycles.seed = 1
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"

    # An orthographic camera on -X looking along +X, +Z up: the image spans [-1.25, 1.25].
    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 2.5
    cam = bpy.data.objects.new("camera", cam_data)
    cam.matrix_world = Matrix(((0, 0, -1, -10), (-1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 0, 1)))
    scene.collection.objects.link(cam)
    scene.camera = cam

    # The sphere: a finely subdivided icosphere, smooth shaded (normals within ~1e-4 of a sphere's).
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=7, radius=1.0)
    sphere = bpy.context.active_object
    bpy.ops.object.shade_smooth()

    world = bpy.data.worlds.new("world")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    if env.startswith("constant:"):
        v = float(env.split(":", 1)[1])
        background.inputs["Color"].default_value = (v, v, v, 1.0)
    else:
        tex = nodes.new("ShaderNodeTexEnvironment")
        tex.image = bpy.data.images.load(os.path.abspath(env))
        tex.image.colorspace_settings.name = "Linear"
        tex.interpolation = "Closest"  # halfback looks the map up per pixel, unfiltered
        links.new(tex.outputs["Color"], background.inputs["Color"])
    background.inputs["Strength"].default_value = 1.0

    before = set(bpy.data.materials.keys())
    with open(material_script) as f:
        exec(compile(f.read(), material_script, "exec"), {"__name__": "halfback_material"})
    made = [m for m in bpy.data.materials.keys() if m not in before]
    if len(made) != 1:
        raise RuntimeError(f"{material_script}: made {len(made)} materials, expected one")
    sphere.data.materials.append(bpy.data.materials[made[0]])
    return scene


def render_to_npy(scene, out):
    exr = out + ".exr"
    scene.render.filepath = exr
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(exr)
    w, h = img.size
    pixels = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)[::-1, :, :3]
    np.save(out, pixels)
    os.remove(exr)


def main():
    args = sys.argv[sys.argv.index("--") + 1:]
    if len(args) != 5:
        raise SystemExit("usage: blender -b --python blender_sphere.py -- MATERIAL.py ENV OUT.npy SIZE SPP")
    material_script, env, out, size, spp = args
    render_to_npy(build_scene(material_script, env, int(size), int(spp)), out)


main()
