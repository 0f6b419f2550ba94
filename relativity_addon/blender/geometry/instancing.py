"""Instancers on the Apparent Geometry path: what the modifier cannot draw right, in one line.

The modifier moves a mesh's own vertices to where they are seen, computed where the object is. An
instance drawn elsewhere (a collection instance, a particle system, geometry-nodes or vertex and
face instancing) shows the geometry computed for the source object's place, and instances a
moving mesh draws are not moved at all: refused by name (:func:`check_instancing`). With a moving
observer the boosted-mesh preview carries every mesh into the camera frame, so instances of
meshes at rest are wrong there too: refused when the final render is the preview, a viewport
warning when it is the exact camera.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ...errors import RelativityError
from ..common import busy
from ..scene import moving_objects
from . import modifier
from .modifier import applied_objects

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable, Iterator

    from bpy.types import Depsgraph, Object, Scene

    from ..scene.snapshot import Snapshot


def _may_instance(obj: Object) -> bool:
    """Whether ``obj`` can draw instances: a collection, vertex or face instancer, a particle
    system, or geometry nodes of the user's (cheap: tells which scenes need the instance scan)."""
    if obj.instance_type != "NONE" or len(getattr(obj, "particle_systems", ())):
        return True
    ours = False  # the add-on's own modifier: the first that runs its group (find_modifier)
    for each in obj.modifiers:
        if each.type != "NODES":
            continue
        if not ours and modifier.is_relativity_modifier(each):
            ours = True
            continue
        return True
    return False


def _instanced_by_settings(obj: Object) -> Iterator[Object]:
    """The objects ``obj`` draws again by its settings: a collection instance's objects, its
    particle systems' instance object or collection (whether or not they are in the scene)."""
    if obj.instance_type == "COLLECTION" and obj.instance_collection is not None:
        yield from obj.instance_collection.all_objects
    for system in getattr(obj, "particle_systems", ()):
        settings = system.settings
        if settings.render_type == "OBJECT" and settings.instance_object is not None:
            yield settings.instance_object
        elif settings.render_type == "COLLECTION" and settings.instance_collection is not None:
            yield from settings.instance_collection.all_objects


def _drawn_elsewhere(instancer: Object, source: Object) -> str:
    return (
        f"{moving_objects.object_label(instancer)} draws {moving_objects.object_label(source)} (which has its own "
        "velocity) away from where its apparent geometry is computed: make the instances real (Make Instances "
        f"Real) or set the Motion of {source.name!r} to Static"
    )


def _instancing(
    depsgraph: Depsgraph | None,
    drawn: Callable[[Object], bool],
    evaluated: set[str],
    scene_objects: Iterable[Object],
    instancers: list[Object] | None = None,
) -> tuple[Object | None, Object] | None:
    """``(instancer, source)``: an instancer among ``scene_objects`` that draws again an object for
    which ``drawn`` is true (by its settings: a collection instance, a particle system, in the scene
    or not) or, in the evaluated scene, one named in ``evaluated``; ``(None, source)``: an object
    named in ``evaluated`` that draws instances or other components the modifier does not move;
    None when neither happens. ``instancers``: :func:`_may_instance`'s of ``scene_objects``, when
    already listed."""
    if instancers is None:  # only these can draw anything again (one pass over the scene)
        instancers = [obj for obj in scene_objects if _may_instance(obj)]
    for instancer in instancers:
        for source in _instanced_by_settings(instancer):
            if drawn(source):
                return instancer, source
    if not evaluated or not instancers:
        return None
    if depsgraph is None:
        with busy.computing():  # the update handlers this evaluation runs must not sync again
            depsgraph = bpy.context.evaluated_depsgraph_get()
    for instance in depsgraph.object_instances:
        parent = instance.parent
        if not instance.is_instance or parent is None:
            continue
        drawer, drawn_object = parent.original, instance.object.original
        if drawer is not None and drawer.name in evaluated:
            return None, drawer
        if drawn_object is not None and drawn_object.name in evaluated:
            return drawer, drawn_object
    return None


def instancing_problem(
    depsgraph: Depsgraph | None,
    objects: Iterable[Object],
    scene_objects: Iterable[Object],
    instancers: list[Object] | None = None,
) -> str | None:
    """Why the evaluated scene (``depsgraph``, evaluated if None and needed) cannot be drawn right
    (one line), or None: one of the moving ``objects`` (those with their own velocity) draws
    instances or other components the modifier does not move (geometry nodes, particles, vertex or
    face instancing), or an instancer among ``scene_objects`` (a collection instance, a particle
    system, geometry nodes) draws one of them elsewhere: the instance shows the apparent geometry
    computed where the object itself is (or, for an object only instanced, none). Objects drawn by
    a collection instance or a particle system are checked by their settings, in the scene or not."""
    moving = {obj.name for obj in objects if moving_objects.has_own_velocity(obj)}
    found = _instancing(depsgraph, moving_objects.has_own_velocity, moving, scene_objects, instancers)
    if found is None:
        return None
    instancer, source = found
    if instancer is None:
        return (
            f"Mesh {source.name!r} draws instances or other geometry (geometry nodes, particles or "
            "instancing) that cannot move on the Apparent Geometry path yet: make them real (Realize Instances)"
        )
    return _drawn_elsewhere(instancer, source)


def preview_instancing_problem(
    depsgraph: Depsgraph | None,
    objects: Iterable[Object],
    scene_objects: Iterable[Object],
    instancers: list[Object] | None = None,
) -> str | None:
    """The same for the boosted-mesh preview of a moving observer, where every mesh of ``objects``
    (the applied ones, moving or not) is drawn as seen from the moving camera: an instance of one of
    them elsewhere shows it as seen where the mesh itself is, and instances a mesh draws are not
    boosted at all. One line (to follow with what to do), or None."""
    scene_objects = list(scene_objects)
    applied = {obj.name for obj in objects}
    in_scene = {obj.name for obj in scene_objects}
    found = _instancing(
        depsgraph,
        lambda obj: obj.type == "MESH" and (obj.name in applied or obj.name not in in_scene),
        applied,
        scene_objects,
        instancers,
    )
    if found is None:
        return None
    instancer, source = found
    if instancer is None:
        return (
            f"Mesh {source.name!r} draws instances or other geometry that the boosted-mesh preview of a moving "
            "observer does not carry into the camera frame"
        )
    return (
        f"{moving_objects.object_label(instancer)} draws {moving_objects.object_label(source)} again: the "
        f"boosted-mesh preview of a moving observer shows it as seen where {source.name!r} is, not where the "
        "instance stands"
    )


# Scene name -> the instancing problem found at its last sync that evaluated the scene, and the
# preview's problem (its own line: refused when the final render is the preview, else a warning).
_instancing_problems = {}
_preview_problems = {}


def check_instancing(
    scene: Scene, depsgraph: Depsgraph | None = None, evaluate: bool = True, preview: str | None = None
) -> None:
    """RelativityError (one line) when an instancer draws a moving mesh or a moving mesh draws
    instances (:func:`instancing_problem`), as found at Set Up or after an edit. ``evaluate=False``
    (a sync without the frame's evaluated meshes) repeats what the last evaluating check found.
    ``preview``: None when the meshes are not boosted (observer at rest, or the exact camera's
    final render); else "RENDER" when the final render is the boosted-mesh preview (its instancing
    problems are refused) or "VIEWPORT" (only the viewport shows it: a warning,
    :func:`instancing_warnings`)."""
    if evaluate:
        objects = applied_objects(scene)
        instancers = [obj for obj in scene.objects if _may_instance(obj)]  # once for both checks
        # (no object that may instance: neither check finds anything, and neither lists the movers)
        found: tuple[str | None, str | None] = (None, None)
        if instancers:
            found = (
                instancing_problem(depsgraph, objects, scene.objects, instancers),
                preview_instancing_problem(depsgraph, objects, scene.objects, instancers),
            )
        _instancing_problems[scene.name], _preview_problems[scene.name] = found
    problem = _instancing_problems.get(scene.name)
    if problem is not None:
        raise RelativityError(problem)
    problem = _preview_problems.get(scene.name)
    if problem is not None and preview == "RENDER":
        raise RelativityError(
            f"{problem}: make the instances real (Make Instances Real), or set Final Render to Exact Camera"
        )


def instancing_warnings(scene: Scene, snap: Snapshot) -> list[str]:
    """The viewport's boosted-mesh preview problem found at the last check (the exact camera's final
    render draws those instances right), as a one-line warning; empty when there is none."""
    problem = _preview_problems.get(scene.name)
    if problem is None or not boosted(snap):
        return []
    return [f"{problem} (in the viewport only: the final render with the exact camera is right)"]


def boosted(snap: Snapshot) -> bool:
    """Whether the meshes are drawn as the boosted-mesh preview of a moving observer."""
    return snap.method == "GEOMETRY" and not snap.exact_camera and any(snap.beta)


def forget(scene_name: str) -> None:
    """Drop what the last checks found for the scene (Set Up checked again, or Remove)."""
    _instancing_problems.pop(scene_name, None)
    _preview_problems.pop(scene_name, None)
