# Run by tests/client/blender_vdb.sh inside Blender (3.4 or later), headless:
#   blender -b --factory-startup --python-exit-code 1 --python blender_vdb.py -- \
#       FILE.vdb UNIT_M VOXEL_MM EXTENT_MM GRIDS [PICTURE.png]
# Imports FILE.vdb as a volume object the way File > Import > OpenVDB does, and checks what
# Blender makes of it: the grids by name with their types, each grid's transform (voxel edge
# VOXEL_MM x UNIT_M metres, index 0 at the centre of the first voxel) and the object's bounding
# box, which Blender takes from the active voxels' centres: (v/2, extent - v/2) x UNIT_M for a
# box [0, extent] sampled from its corner. With PICTURE: renders the volume with Cycles on the
# CPU from above (orthographic, 160 x 120, transparent film) and checks that the covered pixels
# are the box's projected rectangle and that its colour reached the renderer.
import sys
import bpy

args = sys.argv[sys.argv.index("--") + 1:]
path, unit, voxel_mm = args[0], float(args[1]), float(args[2])
extent_mm = [float(x) for x in args[3].split(",")]
grids_expected = dict(g.split(":") for g in args[4].split(","))   # name:type
picture = args[5] if len(args) > 5 else None


def check(ok, what):
    if not ok:
        raise SystemExit("blender_vdb.py: " + what)


bpy.ops.object.volume_import(filepath=path)
obj = bpy.context.selected_objects[0]
check(obj.type == "VOLUME", f"imported a {obj.type}, expected a VOLUME object")
vol = obj.data
vol.grids.load()
check(vol.grids.is_loaded, "grids not loaded: " + vol.grids.error_message)
found = {g.name: g.data_type for g in vol.grids}
check(found == grids_expected, f"grids {sorted(found.items())}, expected {sorted(grids_expected.items())}")

v = voxel_mm * unit
for g in vol.grids:
    m = g.matrix_object
    for a in range(3):
        check(abs(m[a][a] - v) <= 1e-9 * max(1.0, v / 1e-3), f"{g.name}: scale {m[a][a]}, expected {v}")
        check(abs(m[a][3] - v / 2) <= 1e-9 * max(1.0, v / 1e-3), f"{g.name}: translation {m[a][3]}, expected {v / 2}")

bpy.context.view_layer.update()
box = obj.bound_box
lo = [min(c[a] for c in box) for a in range(3)]
hi = [max(c[a] for c in box) for a in range(3)]
for a in range(3):
    want_lo, want_hi = v / 2, (extent_mm[a] - voxel_mm / 2) * unit
    # Blender keeps the box in 32-bit floats.
    tol = 1e-6 * extent_mm[a] * unit
    check(abs(lo[a] - want_lo) <= tol and abs(hi[a] - want_hi) <= tol,
          f"bounding box axis {a}: {lo[a]} .. {hi[a]}, expected {want_lo} .. {want_hi}")
print(f"blender_vdb.py: {len(found)} grids; box {lo} .. {hi}")

if picture:
    scene = bpy.context.scene
    for o in list(scene.objects):                 # the factory scene's cube, camera and lamp
        if o is not obj:
            bpy.data.objects.remove(o)
    # A volume material: density and colour from the grids of those names (Blender's meaning).
    mat = bpy.data.materials.new("trivox")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    for n in list(nodes):
        nodes.remove(n)
    out = nodes.new("ShaderNodeOutputMaterial")
    pv = nodes.new("ShaderNodeVolumePrincipled")
    pv.inputs["Density"].default_value = 2.0 / (min(extent_mm) * unit)   # optical depth 2 at least
    pv.inputs["Density Attribute"].default_value = "density"
    pv.inputs["Color Attribute"].default_value = "color"
    mat.node_tree.links.new(pv.outputs["Volume"], out.inputs["Volume"])
    vol.materials.append(mat)
    # Camera straight down on the box's centre; the picture is 2 box widths wide.
    cx, cy = extent_mm[0] * unit / 2, extent_mm[1] * unit / 2
    cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2 * extent_mm[0] * unit
    cam.data.clip_start, cam.data.clip_end = 1e-3 * unit, 100 * extent_mm[2] * unit
    cam.location = (cx, cy, 10 * extent_mm[2] * unit)
    scene.collection.objects.link(cam)
    scene.camera = cam
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 3.0
    scene.collection.objects.link(sun)
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 4
    scene.cycles.use_denoising = False            # Debian's build has no OpenImageDenoise
    scene.cycles.volume_step_rate = 4.0
    scene.render.resolution_x, scene.render.resolution_y = 160, 120
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = True
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGBA"
    scene.render.filepath = picture
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(picture)
    px = list(img.pixels)
    W, H = img.size
    covered = [px[4 * i:4 * i + 4] for i in range(W * H) if px[4 * i + 3] > 0.5]
    # The box seen from above: extent x by extent y, at 160 / (2 extent x) pixels per unit.
    per = W / (2 * extent_mm[0])
    want = extent_mm[0] * per * extent_mm[1] * per
    print(f"blender_vdb.py: {W} x {H} pixels, {len(covered)} covered (the box's rectangle: {want:.0f})")
    check(abs(len(covered) - want) <= 0.1 * want, f"{len(covered)} covered pixels, expected {want:.0f} within 10%")
    # The colour grid reached the shader: the model is orange (r > g > b).
    mean = [sum(p[q] for p in covered) / len(covered) for q in range(3)]
    check(mean[0] > mean[1] > mean[2], f"mean colour {mean}, expected orange (r > g > b)")
    print(f"blender_vdb.py: mean colour of the covered pixels {[round(x, 3) for x in mean]}")
