import bpy

scene = bpy.context.scene
# The real speed of light, 299 792 458 m/s; in scene units per second (one scene unit = unit scale metres).
scene.relativity.speed_of_light = 299792458.0 / (scene.unit_settings.scale_length or 1.0)
