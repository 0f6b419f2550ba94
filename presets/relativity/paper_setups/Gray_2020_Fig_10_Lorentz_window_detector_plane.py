import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# Gray et al. (2020) Fig. 10: the Fig. 9 set-up (beta = (0.1, 0, 0.99) in Dr TIM axes, i.e.
# (0.1, 0, -0.99) in the camera's local axes; c = 1; Lorentz window in the plane of spatial fixed
# points for t = -1, eq. 6) photographed with the detector-plane shutter (ideal lens) instead of
# the shutter in the window. The window then undoes the distortion only imperfectly.
# As in the paper, the shutter time is chosen so that the chief ray along the optical axis has
# Fig. 9's timing: it crosses Fig. 9's shutter plane (through (0.111, 0, -1.1), normal beta) at
# t = -1, reaches the lens centre a distance a later and the detector, |D| behind the lens (thin
# lens on the axis; focus at infinity without depth of field), another |D| later.
if scene.camera is not None:
    to_world = scene.camera.matrix_world.to_quaternion()
    beta_local = Vector((0.1, 0.0, -0.99))
    settings.velocity_source = "MANUAL"
    settings.beta = to_world @ beta_local
    settings.method = "CAMERA"
    settings.use_time_of_flight = False
    settings.speed_of_light = 1.0
    settings.shutter_plane_point = (0.111, 0.0, -1.1)
    settings.shutter_plane_normal = (0.1, 0.0, -0.99)
    settings.use_lorentz_window = True
    settings.lorentz_window_shutter = "SHUTTER_MODEL"
    settings.lorentz_window_time = -1.0
    settings.shutter_model = "DETECTOR_PLANE"
    settings.imaging_element = "IDEAL_LENS"
    normal = beta_local.normalized()
    axial_path = Vector((0.111, 0.0, -1.1)).dot(normal) / Vector((0.0, 0.0, -1.0)).dot(normal)
    camera = scene.camera.data
    focal_length = camera.lens * 1e-3 / (scene.unit_settings.scale_length or 1.0)
    focus = camera.dof.focus_distance if camera.dof.use_dof else 0.0
    image_distance = 1.0 / (1.0 / focal_length - 1.0 / focus) if focus > focal_length else focal_length
    settings.shutter_time = -1.0 + (axial_path + image_distance) / settings.speed_of_light
