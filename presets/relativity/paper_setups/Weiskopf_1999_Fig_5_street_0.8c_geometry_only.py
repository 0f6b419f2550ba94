import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# Weiskopf, Kraus, Ruder (1999) Fig. 5 (geometry only): entering a street (boxes and lights at rest) at 0.8 c along
# the camera's view direction (its local -Z, in world axes).
if scene.camera is not None:
    settings.velocity_source = "MANUAL"
    settings.beta = scene.camera.matrix_world.to_quaternion() @ Vector((0.0, 0.0, -0.8))
    settings.method = "CAMERA"
    settings.use_time_of_flight = False
    settings.use_geometry = True
    settings.use_doppler = False
    settings.use_searchlight = False
