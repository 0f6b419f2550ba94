import bpy
from mathutils import Vector

scene = bpy.context.scene
settings = scene.relativity
# |beta| = 0.5: keep the direction of the current velocity; from rest, move along the camera's
# view direction (its local -Z).
direction = Vector(settings.beta)
if direction.length == 0.0 and scene.camera is not None:
    direction = scene.camera.matrix_world.to_quaternion() @ Vector((0.0, 0.0, -1.0))
if direction.length > 0.0:
    settings.velocity_source = "MANUAL"
    settings.beta = direction.normalized() * 0.5
