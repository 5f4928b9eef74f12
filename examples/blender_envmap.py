"""Light a Blender scene with an atmos sky: the environment map plus the sun lamp.

Make the map and the sun's numbers with atmos, then run this script in Blender
(headless Cycles):

    atmos render --model bruneton --camera projection=equirect \\
        --sun elevation=30,azimuth=120 --size 1024x512 -o sky.exr
    atmos irradiance --model bruneton --sun elevation=30,azimuth=120   # direct, diffuse
    blender -b --factory-startup -P examples/blender_envmap.py -- \\
        --map sky.exr --elevation 30 --azimuth 120 --direct R G B [--out plane.exr]

The scene is a white Lambertian plane (albedo 1) seen from above by an
orthographic camera, lit by the map (World > Environment Texture,
equirectangular) and a sun lamp. The script prints the plane's mean radiance
("RADIANCE r g b"), which should equal (direct + diffuse) / pi from
`atmos irradiance` (tests/scripts/blender_envmap_test.py checks it within 3 %).

Conventions (docs/views.md): atmos's equirect map has north at its left edge
and east a quarter across; Blender's equirectangular lookup puts its image
edge at Blender's +X and a quarter across at -Y. So atmos's north is Blender's
+X, east -Y, up +Z, and the sun lamp points along -(cos e cos a, -cos e sin a,
sin e). The map holds the sky without the sun's disc (no --sun-disc): the lamp
is the sun. `--direct` is the sun's irradiance on the horizontal plane (atmos
irradiance's direct row); the lamp's strength is that divided by sin(e)
(Blender's sun strength is the irradiance normal to the light, W m^-2, in
scene units), its colour the per-channel ratio.
"""

import math
import sys

import bpy


def parse_args(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    opts = {"out": "/tmp/atmos_blender_plane.exr", "samples": "64", "size": "32"}
    i = 0
    while i < len(args):
        key = args[i].lstrip("-")
        if key == "direct":
            opts[key] = [float(v) for v in args[i + 1:i + 4]]
            i += 4
        else:
            opts[key] = args[i + 1]
            i += 2
    for key in ("map", "elevation", "azimuth", "direct"):
        if key not in opts:
            sys.exit("blender_envmap.py: missing --" + key)
    return opts


def main():
    o = parse_args(sys.argv)
    elevation = math.radians(float(o["elevation"]))
    azimuth = math.radians(float(o["azimuth"]))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = int(o["samples"])
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.max_bounces = 1
    scene.cycles.diffuse_bounces = 1
    scene.cycles.sample_clamp_direct = 0.0
    scene.cycles.sample_clamp_indirect = 0.0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    size = int(o["size"])
    scene.render.resolution_x = size
    scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False

    # World: the equirect map at strength 1 (its values are radiance).
    world = bpy.data.worlds.new("atmos")
    scene.world = world
    world.use_nodes = True
    nodes, links = world.node_tree.nodes, world.node_tree.links
    nodes.clear()
    tex = nodes.new("ShaderNodeTexEnvironment")
    tex.image = bpy.data.images.load(o["map"])
    tex.image.colorspace_settings.name = "Linear"
    tex.projection = "EQUIRECTANGULAR"
    tex.interpolation = "Linear"
    background = nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = 1.0
    output = nodes.new("ShaderNodeOutputWorld")
    links.new(tex.outputs["Color"], background.inputs["Color"])
    links.new(background.outputs["Background"], output.inputs["Surface"])

    # The sun lamp: normal irradiance per channel = direct / sin(e).
    direct = o["direct"]
    normal = [d / math.sin(elevation) for d in direct]
    strength = max(normal)
    sun = bpy.data.lights.new("sun", type="SUN")
    sun.energy = strength
    sun.color = [v / strength for v in normal]
    sun.angle = math.radians(0.53)
    sun_object = bpy.data.objects.new("sun", sun)
    scene.collection.objects.link(sun_object)
    # Toward the sun in Blender axes (north +X, east -Y, up +Z).
    to_sun = (math.cos(elevation) * math.cos(azimuth), -math.cos(elevation) * math.sin(azimuth),
              math.sin(elevation))
    # A sun lamp shines along its local -Z: rotate -Z onto -to_sun.
    from mathutils import Vector
    sun_object.rotation_mode = "QUATERNION"
    sun_object.rotation_quaternion = Vector(to_sun).to_track_quat("Z", "Y")

    # A white Lambertian plane (albedo 1), 100 m across, and an orthographic
    # camera 1 m above its centre looking down at 1 m of it.
    bpy.ops.mesh.primitive_plane_add(size=100.0, location=(0.0, 0.0, 0.0))
    plane = bpy.context.active_object
    material = bpy.data.materials.new("white")
    material.use_nodes = True
    mn, ml = material.node_tree.nodes, material.node_tree.links
    mn.clear()
    diffuse = mn.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    diffuse.inputs["Roughness"].default_value = 0.0
    mout = mn.new("ShaderNodeOutputMaterial")
    ml.new(diffuse.outputs["BSDF"], mout.inputs["Surface"])
    plane.data.materials.append(material)
    cam_data = bpy.data.cameras.new("camera")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 1.0
    camera = bpy.data.objects.new("camera", cam_data)
    camera.location = (0.0, 0.0, 1.0)
    camera.rotation_euler = (0.0, 0.0, 0.0)  # looks down -Z
    scene.collection.objects.link(camera)
    scene.camera = camera

    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = o["out"]
    bpy.ops.render.render(write_still=True)

    image = bpy.data.images.load(o["out"])
    pixels = list(image.pixels)
    n = len(pixels) // 4
    mean = [sum(pixels[c::4]) / n for c in range(3)]
    print("RADIANCE %.9g %.9g %.9g" % tuple(mean))


main()
