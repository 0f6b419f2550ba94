import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# Weiskopf, Kraus, Ruder (1999) Fig. 9 (Doppler and searchlight): the Sun (blackbody 5762 K) passing by at 0.5 c. The
# camera method moves the observer instead: a camera moving at 0.5 c along its local +X sees a Sun at
# rest pass by to the left (the same relative motion, the photo taken in the camera's frame).
if scene.camera is not None:
    settings.velocity_source = "MANUAL"
    settings.beta = scene.camera.matrix_world.to_quaternion() @ Vector((0.5, 0.0, 0.0))
    settings.method = "CAMERA"
    settings.use_time_of_flight = False
    settings.use_geometry = True
    settings.use_doppler = True
    settings.use_searchlight = True
