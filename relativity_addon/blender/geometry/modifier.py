"""The apparent-geometry modifier and its per-object cache.

The add-on's modifier (node group ``Relativity Apparent Geometry``, ``node_group.py``) subdivides the mesh, stores
the tessellated rest positions in the point attribute ``relativity_rest``, then sets the positions
sampled by index from a cache mesh object, but only when the point counts match (so a stale cache
never scrambles the mesh); it also copies the cache's ``relativity_beta`` (each point's velocity
relative to the observer) for the Doppler shaders. ``geometry.update_object`` fills the cache.
For the closed-form motions (``motion.closed_form``: Static, Constant Velocity without an animation
of its own) the modifier computes the apparent positions itself (``Closed Form`` on, the inputs of
``uniform_motion.closed_form_inputs``), from the rest positions with vector math: a velocity change or a frame
step sets a few inputs and needs no cache and no pass over the vertices in Python. Where the
edges' bound clears such a mesh the modifier has the lean group instead (``node_group.LEAN_WHEN``,
``names.LEAN_GEOMETRY_GROUP``): the same output from the closed form's nodes alone; :func:`set_inputs`
gives each modifier the group its inputs call for.

The cache object is not linked into any scene; the modifier holds its only user, so it is saved
with the .blend and a render farm worker needs nothing else. Motion and deformation bakes are
kept on the cache mesh too (``bakes.py``), so they go with the effect when it is removed.
"""

from __future__ import annotations

from array import array
from typing import TYPE_CHECKING, cast

import bpy
import numpy as np

from ..common import compat, names, once
from ..common.nodes import ensure_group, interface_identifier, remove_unused_groups
from .node_group import LEAN_WHEN, lean_node_group_spec, node_group_spec

if TYPE_CHECKING:
    from collections.abc import Iterable
    from contextlib import AbstractContextManager

    from bpy.types import ID, Depsgraph, Mesh, Modifier, NodeTree, Object, Scene

    from ...physics.arrays import FloatArray


# Inputs whose values the modifiers keep across a rebuild of the group (an older version's file):
# the rest the next update sets again.
KEPT_INPUTS = ("Cache", "Tessellation", "Face Codes", "Weld Distance")


GROUPS = (names.GEOMETRY_GROUP, names.LEAN_GEOMETRY_GROUP)


def ensure_node_group() -> NodeTree:
    """The node group, rebuilt when a file holds another version of it. The rebuilt interface's
    sockets get new identifiers, so the modifiers' values (the cache, where the bakes live) are
    read by name before and set again after."""
    return _ensure(names.GEOMETRY_GROUP, names.GEOMETRY_GROUP_VERSION)


def ensure_lean_group() -> NodeTree:
    """The lean group (``node_group.lean_node_group_spec``), rebuilt as :func:`ensure_node_group`."""
    return _ensure(names.LEAN_GEOMETRY_GROUP, names.LEAN_GEOMETRY_GROUP_VERSION)


def _ensure(name: str, version: int) -> NodeTree:
    tree = bpy.data.node_groups.get(name)
    if tree is not None and tree.get(names.GEOMETRY_GROUP_VERSION_KEY) == version:
        return tree  # current: the spec is not built (at every update it cost more than the rest of the check)
    kept = []
    rebuilt = tree is not None
    if rebuilt:
        old = {item.name: item.identifier for item in tree.interface.items_tree if item.item_type == "SOCKET"}
        for obj in bpy.data.objects:
            for mod in obj.modifiers:
                if mod.type == "NODES" and mod.node_group == tree:
                    values = {name: compat.modifier_input(mod, old[name]) for name in KEPT_INPUTS if name in old}
                    kept.append((mod, values))
    spec = node_group_spec() if name == names.GEOMETRY_GROUP else lean_node_group_spec()
    group = ensure_group(spec, names.GEOMETRY_GROUP_VERSION_KEY, version)
    if rebuilt:  # new socket identifiers; the signatures are deleted below: no object is current
        _identifiers.clear()
        _generation[0] += 1
    for mod, values in kept:
        for name, value in values.items():
            if value is not None:
                compat.set_modifier_input(mod, interface_identifier(group, name), value)
        cache = values.get("Cache")
        if cache is not None and cache.data is not None and names.SIGNATURE_KEY in cache.data:
            del cache.data[names.SIGNATURE_KEY]  # the next sync sets the new inputs
    return group


_generation = [0]


def group_generation() -> int:
    """How many times this session rebuilt the node group of a file's modifiers (which deletes
    their signatures: part of ``apparent_meshes.scene_key``)."""
    return _generation[0]


def is_relativity_modifier(modifier: Modifier) -> bool:
    """Whether ``modifier`` runs one of the add-on's node groups (the full or the lean one)."""
    return modifier.type == "NODES" and modifier.node_group is not None and modifier.node_group.name in GROUPS


def find_modifier(obj: Object) -> Modifier | None:
    for modifier in obj.modifiers:
        if is_relativity_modifier(modifier):
            return modifier
    return None


def is_cache(obj: Object) -> bool:
    """A cache object (its mesh records the object it serves), never an object of the user's."""
    return obj.type == "MESH" and obj.data is not None and names.OWNER_KEY in obj.data


# Inside listed_once(): scene name -> its applied objects, (name, "moving") -> the moving ones.
_listed = once.Once()


def listed_once() -> AbstractContextManager[None]:
    """Inside: :func:`applied_objects` lists each scene's meshes once (a sync adds or removes no
    modifier), not again in every part that asks."""
    return _listed.kept()


def listed_as(scene: Scene, objects: tuple[Object, ...]) -> None:
    """Inside :func:`listed_once`: ``objects`` are the scene's applied meshes (a sync that knows them)."""
    scenes = _listed.values()
    if scenes is not None:
        scenes[scene.name] = objects


def applied_objects(scene: Scene) -> list[Object]:
    """The scene's meshes carrying the modifier; linked objects are the library's (set up there or
    not), never this file's."""
    scenes = _listed.values()
    if scenes is not None and scene.name in scenes:
        return list(scenes[scene.name])
    found = [obj for obj in scene.objects if _applied(obj)]
    if scenes is not None:
        scenes[scene.name] = tuple(found)
    return found


def _applied(obj: Object) -> bool:
    return obj.type == "MESH" and obj.library is None and find_modifier(obj) is not None and not is_cache(obj)


def any_applied(scene: Scene) -> bool:
    """Whether the scene holds a mesh carrying the modifier (:func:`applied_objects` not empty;
    stops at the first)."""
    scenes = _listed.values()
    if scenes is not None and scene.name in scenes:
        return bool(scenes[scene.name])
    return any(_applied(obj) for obj in scene.objects)


def moving_objects(scene: Scene) -> list[Object]:
    """The scene's set-up meshes that have a motion of their own (cheap: no positions; listed once
    inside :func:`listed_once`, where the lamp and bounce stages ask three times)."""
    scenes = _listed.values()
    key = (scene.name, "moving")
    if scenes is not None and key in scenes:
        return list(scenes[key])
    found = []
    for obj in applied_objects(scene):
        settings = obj.relativity
        if (settings.motion == "CONSTANT" and any(settings.beta)) or (
            settings.motion == "ANIMATION" and not settings.use_deformation
        ):
            found.append(obj)
    if scenes is not None:
        scenes[key] = tuple(found)
    return found


def cache_object(obj: Object, modifier: Modifier | None = None) -> Object | None:
    """The cache object of ``obj`` (of its ``modifier``, found when not given), or None."""
    modifier = modifier or find_modifier(obj)
    if modifier is None:
        return None
    return compat.modifier_input(modifier, _identifier(modifier.node_group, "Cache"))


def cache_data(obj: Object, modifier: Modifier | None = None) -> ID | None:
    """The cache mesh of ``obj`` (where its update state and bakes live; ``modifier``: its modifier,
    found when not given), or None."""
    cache = cache_object(obj, modifier)
    return cache.data if cache is not None else None


def ensure_modifier(obj: Object) -> tuple[Modifier, Object]:
    """The object's modifier and cache object, created if missing. Returns (modifier, cache)."""
    group = ensure_node_group()
    modifier = find_modifier(obj)
    created = modifier is None
    if modifier is None:
        modifier = obj.modifiers.new(names.GEOMETRY_MODIFIER, "NODES")
        modifier.node_group = group
    elif modifier.node_group != group:  # the lean group (set_inputs), at its version
        group = ensure_lean_group()
        if modifier.node_group != group:
            _give_group(modifier, group)
    cache = cache_object(obj)
    if cache is not None and _shared_with_another_object(obj, cache):
        cache = None  # a duplicated object copied the modifier and its cache pointer: own one
    if cache is None:
        mesh = bpy.data.meshes.new(f"{names.CACHE_PREFIX} {obj.name}")
        cache = bpy.data.objects.new(f"{names.CACHE_PREFIX} {obj.name}", mesh)
        compat.set_modifier_input(modifier, interface_identifier(group, "Cache"), cache)
    if cache.data.get(names.OWNER_KEY) != obj.name:
        cache.data[names.OWNER_KEY] = obj.name  # set on creation, and follows a rename
    # with adaptive tessellation the update sets the level (geometry/tessellation.py); a new
    # modifier starts with none, so Set Up never subdivides a large mesh it may not need to
    adaptive = bool(obj.relativity.use_adaptive_tessellation)
    if created or not adaptive:
        identifier = _identifier(group, "Tessellation")
        level = 0 if adaptive else int(obj.relativity.tessellation)
        if compat.modifier_input(modifier, identifier) != level:
            compat.set_modifier_input(modifier, identifier, level)
            obj.update_tag()  # a modifier input is no tagged property: re-evaluate before reading the rest
    enabled = bool(obj.relativity.enabled)
    if modifier.show_viewport != enabled or modifier.show_render != enabled:
        modifier.show_viewport = modifier.show_render = enabled
    return modifier, cache


def set_closed_form(mod: Modifier, inputs: dict[str, tuple[float, ...] | float] | None) -> bool:
    """Switch the modifier's closed form on with ``inputs`` (by interface name), or off (None: the
    cache's positions). Returns whether any input changed (the object must then be evaluated
    again). Values equal after rounding to the sockets' float32 are left as they are."""
    return set_inputs(mod, {"Closed Form": inputs is not None, **(inputs or {})})


_identifiers: dict[tuple[int, int, object], dict[str, str]] = {}


def _input_identifiers(group: NodeTree) -> dict[str, str]:
    """Name -> identifier of the group's input sockets, read once per group and version."""
    key = (group.session_uid, group.as_pointer(), group.get(names.GEOMETRY_GROUP_VERSION_KEY))
    known = _identifiers.get(key)
    if known is None:
        known = {
            item.name: item.identifier
            for item in group.interface.items_tree
            if item.item_type == "SOCKET" and item.in_out == "INPUT"
        }
        if len(_identifiers) >= 4:  # the two groups of this file, at most an older version of each
            _identifiers.clear()
        _identifiers[key] = known
    return known


def _plain(value: object) -> object:
    """A modifier input's value as Python data: 4.5's arrays are views into the modifier's
    properties, which another group frees (reading one then crashed Blender)."""
    return tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value


def _give_group(mod: Modifier, group: NodeTree) -> None:
    """Give the modifier ``group`` (the full or the lean one), its inputs' values kept by name
    (the cache above all: the modifier is its only user)."""
    values = {
        name: _plain(compat.modifier_input(mod, ident))
        for name, ident in _input_identifiers(mod.node_group).items()
        if name != "Geometry"  # no value (5.2: no such input property)
    }
    mod.node_group = group
    for name, identifier in _input_identifiers(group).items():
        if values.get(name) is not None:
            compat.set_modifier_input(mod, identifier, values[name])


def is_lean(mod: Modifier) -> bool:
    """Whether the modifier has the lean group (``node_group.LEAN_WHEN``)."""
    return mod.node_group is not None and mod.node_group.name == names.LEAN_GEOMETRY_GROUP


def _identifier(group: NodeTree, name: str) -> str:
    identifier = _input_identifiers(group).get(name)
    return identifier if identifier is not None else interface_identifier(group, name)


def input_identifier(group: NodeTree, name: str) -> str:
    """The identifier of the group's input ``name`` (read once per group and version)."""
    return _identifier(group, name)


def input_value(mod: Modifier, name: str) -> object:
    """The modifier's input ``name`` (by interface name; identifiers read once per group)."""
    return compat.modifier_input(mod, _identifier(mod.node_group, name))


def set_inputs(mod: Modifier, wanted: dict[str, object]) -> bool:
    """Set the modifier's inputs (by interface name) that differ after rounding to float32; returns
    whether any did (or the group changed).

    The group follows the inputs: the lean one while they hold ``node_group.LEAN_WHEN`` (the full
    group would run only the lean one's nodes), the full one as soon as one of those changes (a
    setting, the bound failing, the keyframed solve, the cache's path). The lean group holds every
    input but the keyframed solve's, which are set in the call that turns ``Keyframed`` on."""
    changed = False
    if is_lean(mod) and any(name in LEAN_WHEN and bool(value) != LEAN_WHEN[name] for name, value in wanted.items()):
        _give_group(mod, ensure_node_group())
        changed = True
    identifiers = _input_identifiers(mod.node_group)
    for name, value in wanted.items():
        identifier = identifiers.get(name)
        if identifier is None:
            continue  # an input the lean group does not read
        current = compat.modifier_input(mod, identifier)
        if isinstance(value, bool):
            same = current is not None and bool(current) == value
        else:
            new = _float32s(value)
            same = (
                current is not None
                and hasattr(current, "__len__") == hasattr(value, "__len__")
                and _float32s(current) == new
            )
            value = tuple(new) if hasattr(value, "__len__") else new[0]
        if not same:
            compat.set_modifier_input(mod, identifier, value)
            changed = True
    if not is_lean(mod) and all(
        bool(compat.modifier_input(mod, identifiers[name])) == value for name, value in LEAN_WHEN.items()
    ):
        _give_group(mod, ensure_lean_group())
        changed = True
    return changed


def write_inputs(mod: Modifier, wanted: dict[str, object]) -> None:
    """Set the modifier's number or vector inputs (by interface name, each in its group: the full and the
    lean group hold them alike) to ``wanted``'s values, already rounded to float32 as :func:`set_inputs`
    stores them (tuples of Python floats), comparing nothing."""
    group = mod.node_group
    identifiers = _input_identifiers(group)
    compat.set_modifier_inputs(
        mod, {identifiers.get(name) or _identifier(group, name): value for name, value in wanted.items()}
    )


def _float32s(value: object) -> list[float]:
    """A number or a sequence of numbers rounded to float32 (the sockets' precision), as a list of
    Python floats: compared and written without a numpy array per input (some twenty inputs per
    object and update)."""
    values = cast("Iterable[float]", value if hasattr(value, "__len__") else (value,))
    return array("f", values).tolist()


def closed_form_on(mod: Modifier) -> bool:
    """Whether the modifier computes the apparent positions itself (the closed form, or keyframed
    motion: ``keyframed.py``)."""
    group = mod.node_group
    identifiers = _input_identifiers(group)
    for name in ("Closed Form", "Keyframed"):
        if compat.modifier_input(mod, identifiers.get(name) or _identifier(group, name)):
            return True
    return False


def _shared_with_another_object(obj, cache):
    """True if ``cache`` belongs to another object (its recorded owner) that still uses it."""
    owner = bpy.data.objects.get(cache.data.get(names.OWNER_KEY, "")) if cache.data is not None else None
    return owner is not None and owner != obj and cache_object(owner) == cache


def bake_mesh(obj: Object) -> Mesh | None:
    """The mesh holding the object's deformation bake, or None."""
    data = cache_data(obj)
    if data is None or names.BAKE_KEY not in data:
        return None
    return bpy.data.meshes.get(data[names.BAKE_KEY]["mesh"])


def motion_bake(obj: Object) -> tuple[float, int, FloatArray] | None:
    """``(first frame, samples per frame, matrices (K, 4, 4) float64)`` of the object's motion
    bake, or None."""
    data = cache_data(obj)
    if data is None or names.MOTION_BAKE_KEY not in data:
        return None
    info = data[names.MOTION_BAKE_KEY]
    matrices = np.array(info["matrices"], dtype=np.float64).reshape(-1, 4, 4)
    return float(info["first_frame"]), int(info["samples_per_frame"]), matrices


def motion_bake_range(obj: Object) -> tuple[float, float] | None:
    """(first, last) frame of the object's motion bake, or None (reads no matrices)."""
    data = cache_data(obj)
    if data is None or names.MOTION_BAKE_KEY not in data:
        return None
    info = data[names.MOTION_BAKE_KEY]
    first, per_frame = float(info["first_frame"]), int(info["samples_per_frame"])
    return first, first + (len(info["matrices"]) // 16 - 1) / per_frame


def object_error(obj: Object) -> str | None:
    """The one-line error of the object's last handler update, or None."""
    data = cache_data(obj) if find_modifier(obj) is not None else None
    return data.get(names.ERROR_KEY) or None if data is not None else None


def remove_object_effect(obj: Object, later: list[ID] | None = None) -> bool:
    """Remove the object's modifier, cache and bakes; the mesh data was never written. With
    ``later``, the cache object and its mesh are appended to it for one :func:`remove_later`
    (removing objects one at a time costs a pass over every object of the file each)."""
    modifier = find_modifier(obj)
    if modifier is None:
        return False
    cache = cache_object(obj)
    baked = bake_mesh(obj)
    if cache is not None and _shared_with_another_object(obj, cache):
        cache = baked = None  # the owner keeps them
    obj.modifiers.remove(modifier)
    if baked is not None:
        bpy.data.meshes.remove(baked)
    if cache is not None and later is not None:
        later += [cache, *([cache.data] if isinstance(cache.data, bpy.types.Mesh) else [])]
    elif cache is not None:
        remove_cache(cache, with_bake=False)
    return True


def remove_later(blocks: list[ID]) -> None:
    """Remove the cache objects and meshes :func:`remove_object_effect` set aside, at once (a mesh
    something else still uses stays)."""
    objects = [block for block in blocks if isinstance(block, bpy.types.Object)]
    meshes = [block for block in blocks if isinstance(block, bpy.types.Mesh)]
    bpy.data.batch_remove(objects)
    bpy.data.batch_remove([mesh for mesh in meshes if mesh.users == 0])


def remove_cache(cache: Object, with_bake: bool = True) -> None:
    """Delete a cache object, its mesh and (``with_bake``) the deformation bake it records."""
    mesh = cache.data if isinstance(cache.data, bpy.types.Mesh) else None
    bake_name = mesh.get(names.BAKE_KEY, {}).get("mesh") if with_bake and mesh is not None else None
    bpy.data.objects.remove(cache)
    if mesh is not None and mesh.users == 0:
        bpy.data.meshes.remove(mesh)
    baked = bpy.data.meshes.get(bake_name) if bake_name else None
    if baked is not None and baked.users == 0:
        bpy.data.meshes.remove(baked)


def remove_unused_group() -> None:
    remove_unused_groups(GROUPS)


def evaluated_rest_positions(obj: Object, depsgraph: Depsgraph, dtype: type = np.float64) -> FloatArray | None:
    """The tessellated rest positions (object space, ``(N, 3)`` of ``dtype``) the modifier stored
    on the evaluated mesh, or None without the attribute. Read from the evaluated mesh itself:
    ``to_mesh`` would copy the whole mesh first."""
    obj_eval = obj.evaluated_get(depsgraph)
    mesh = obj_eval.data if obj_eval.type == "MESH" else None
    attribute = mesh.attributes.get(names.REST_ATTRIBUTE) if mesh is not None else None
    if attribute is None:
        return None
    rest = np.empty(len(attribute.data) * 3, dtype=np.float32)
    attribute.data.foreach_get("vector", rest)
    return rest.reshape(-1, 3).astype(dtype, copy=False)


def write_cache(mesh: Mesh, positions: FloatArray, beta: FloatArray, face_codes: FloatArray | None = None) -> None:
    """Object-space positions ``(N, 3)`` and observer-frame velocities ``beta`` (``(N, 3)``, or
    ``(1, 3)`` shared by every point) into the cache mesh; then, with adaptive tessellation, one
    point per face of the modifier's incoming mesh holding its code (``geometry/tessellation.py``)."""
    codes = 0 if face_codes is None else len(face_codes)
    count = len(positions) + codes
    if len(mesh.vertices) != count:
        mesh.clear_geometry()
        mesh.vertices.add(count)
    if codes:
        positions = np.concatenate((positions, np.zeros((codes, 3))))
        if len(beta) > 1:
            beta = np.concatenate((beta, np.zeros((codes, 3))))
    # The attribute API copies the float32 buffer in one go; vertices.foreach_set("co") was
    # measured 150x slower (70 ms for a million vertices).
    if count:  # an empty mesh has no position attribute
        mesh.attributes["position"].data.foreach_set(
            "vector", np.ascontiguousarray(positions, dtype=np.float32).ravel()
        )
    _write_face_codes(mesh, count, face_codes)
    attribute = mesh.attributes.get(names.BETA_ATTRIBUTE)
    if attribute is None:
        attribute = mesh.attributes.new(names.BETA_ATTRIBUTE, "FLOAT_VECTOR", "POINT")
    values = np.empty((count, 3), dtype=np.float32)
    if len(beta) == 1:
        # A shared velocity (constant motion) is usually the one stored at the previous update:
        # reading and comparing costs a fraction of writing. The outcome depends on the data only.
        attribute.data.foreach_get("vector", values.ravel())
        shared = np.asarray(beta[0], dtype=np.float32)
        unchanged = all((values[:, k] == shared[k]).all() for k in range(3))
    else:
        unchanged = False
    if not unchanged:
        values[:] = beta
        attribute.data.foreach_set("vector", values.ravel())
    mesh.update()


def _write_face_codes(mesh, count, face_codes):
    attribute = mesh.attributes.get(names.FACE_CODE_ATTRIBUTE)
    if face_codes is None or len(face_codes) == 0:
        if attribute is not None:
            mesh.attributes.remove(attribute)
        return
    if attribute is None:
        attribute = mesh.attributes.new(names.FACE_CODE_ATTRIBUTE, "FLOAT", "POINT")
    values = np.zeros(count, dtype=np.float32)
    values[count - len(face_codes) :] = face_codes
    attribute.data.foreach_set("value", values)


_object_count = [-1]  # bpy.data.objects' length at the last look for linked caches


def unlink_caches() -> None:
    """Cache objects belong to no collection (the modifier is their only user). Append instantiates
    the loose objects it brings into the active collection, where a cache shows as a second,
    visible mesh: take them out again. Looks only when the number of objects changed."""
    if len(bpy.data.objects) == _object_count[0]:
        return
    _object_count[0] = len(bpy.data.objects)
    for obj in bpy.data.objects:
        if obj.name.startswith(names.CACHE_PREFIX) and obj.library is None and is_cache(obj):
            for collection in obj.users_collection:
                collection.objects.unlink(obj)


def unlinked_objects() -> list[Object]:
    """Meshes of this file carrying the modifier but in no scene (unlinked while set up): linked
    back, they would draw a stale apparent geometry and set the scene up again."""
    return [
        obj
        for obj in bpy.data.objects
        if obj.type == "MESH"
        and obj.library is None
        and not obj.users_scene
        and not is_cache(obj)
        and find_modifier(obj) is not None
    ]


def orphan_caches() -> list[Object]:
    """Cache objects no modifier uses any more (their object was deleted while set up)."""
    return [obj for obj in bpy.data.objects if obj.library is None and obj.users == 0 and is_cache(obj)]
