import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# Gray et al. (2020) Fig. 11: the Fig. 9 set-up (beta = (0.1, 0, 0.99) in Dr TIM axes, i.e.
# (0.1, 0, -0.99) in the camera's local axes; c = 1; shutter and Lorentz window in the plane of
# spatial fixed points through (0.111, 0, 1.1), opening at t_S = -1) seen by a stereo camera: eye
# separation 0.4, convergence plane at distance 5, written as a red-cyan anaglyph. Both eyes share
# the shutter plane and time, so the anaglyph is that of the camera at rest (docs/camera.md, Stereo).
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
    stereo = scene.camera.data.stereo
    stereo.convergence_mode = "OFFAXIS"
    stereo.interocular_distance = 0.4
    stereo.convergence_distance = 5.0
    scene.render.use_multiview = True
    scene.render.views_format = "STEREO_3D"
    scene.render.image_settings.views_format = "STEREO_3D"
    scene.render.image_settings.stereo_3d_format.display_mode = "ANAGLYPH"
