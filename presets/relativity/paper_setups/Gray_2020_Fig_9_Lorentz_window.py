import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# Gray et al. (2020) give beta = (0.1, 0, 0.99) in Dr TIM's left-handed coordinates: x right, y up,
# z into the page (the viewing direction). Blender's camera looks down its local -Z with x right
# and y up, so the same vector in the camera's local axes is (0.1, 0, -0.99) (z flipped; the flip
# of one axis is exactly the change of handedness). It is turned into world axes with the active
# camera's rotation, since scene.relativity.beta is a world vector.
# Fig. 9 and 11: c = 1, shutter in the plane perpendicular to beta through (0.111, 0, 1.1) (Dr TIM),
# i.e. (0.111, 0, -1.1) in the camera's local axes, opening at t_S = -1; that plane is the plane of
# spatial fixed points for t_S (eq. 6), and a Lorentz window in it makes the photo equal the photo
# at rest.
if scene.camera is not None:
    to_world = scene.camera.matrix_world.to_quaternion()
    settings.velocity_source = "MANUAL"
    settings.beta = to_world @ Vector((0.1, 0.0, -0.99))
    settings.method = "CAMERA"
    settings.use_time_of_flight = False
    settings.speed_of_light = 1.0
    settings.shutter_model = "ARBITRARY_PLANE"
    settings.shutter_time = -1.0
    settings.shutter_plane_point = (0.111, 0.0, -1.1)
    settings.shutter_plane_normal = (0.1, 0.0, -0.99)
    settings.use_lorentz_window = True
    settings.lorentz_window_shutter = "WINDOW_PLANE"
