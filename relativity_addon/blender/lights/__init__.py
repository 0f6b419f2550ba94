"""Lamps and lights: moving lights (moving_lights; the exact camera's stand-in lamps on their path,
stand_in_lamps), lamps at rest lighting moving objects (lamps_on_moving_objects, rest_normals) and
lamps seen directly by the exact camera (lamps_seen_directly).
"""
