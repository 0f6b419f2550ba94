import bpy

settings = bpy.context.scene.relativity
settings.shutter_model = "PINHOLE"
settings.shutter_time = 0.0
settings.use_lorentz_window = False
settings.lorentz_window_shutter = "WINDOW_PLANE"
