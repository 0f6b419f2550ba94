import bpy

scene = bpy.context.scene
# Slow light for street scenes: a car at 72 km/h moves at c; in scene units per second
# (one scene unit = unit scale metres).
scene.relativity.speed_of_light = 20.0 / (scene.unit_settings.scale_length or 1.0)
