import bpy

scene = bpy.context.scene
# Slow light for human-scale scenes: a walker at 1.8 m/s moves at 0.9 c; in scene units per second
# (one scene unit = unit scale metres).
scene.relativity.speed_of_light = 2.0 / (scene.unit_settings.scale_length or 1.0)
