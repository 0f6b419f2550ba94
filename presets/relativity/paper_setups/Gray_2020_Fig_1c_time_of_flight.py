import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# Gray et al. (2020) give beta = (0.1, 0, 0.99) in Dr TIM's left-handed coordinates: x right, y up,
# z into the page (the viewing direction). Blender's camera looks down its local -Z with x right
# and y up, so the same vector in the camera's local axes is (0.1, 0, -0.99) (z flipped; the flip
# of one axis is exactly the change of handedness). It is turned into world axes with the active
# camera's rotation, since scene.relativity.beta is a world vector. Fig. 1(c): light-travel time
# only (the Galilean transformation instead of the Lorentz one; no searchlight or Doppler colour),
# pinhole shutter at t_S = 0 (docs/camera.md, "Time of flight only").
if scene.camera is not None:
    to_world = scene.camera.matrix_world.to_quaternion()
    settings.velocity_source = "MANUAL"
    settings.beta = to_world @ Vector((0.1, 0.0, -0.99))
    settings.method = "CAMERA"
    settings.shutter_model = "PINHOLE"
    settings.shutter_time = 0.0
    settings.use_lorentz_window = False
    settings.use_time_of_flight = True  # last: it refuses the Lorentz window
