"""The bounce factor as shader nodes: Cycles' default shading (SVM) and builds without OSL
(docs/lamp-doppler.md, "Light bounced between moving objects", "On SVM: the factor as nodes").

The same factor as ``shaders/relativistic_bounce.osl`` (``physics/bounce.py``),
``F = J (D_s(k) / D_s(k_snap))^4 D_p(k)^2 c_p``, from Light Path (Is Camera Ray, Ray Length),
Geometry (Position, Normal, Incoming) and the emitter's ``relativity_beta`` attribute. Without
``trace()`` the receiver is found by its rest box: each moving object's box is one
:data:`RECEIVER` group node in the scene's group (:func:`scene_group_spec`), and the receiving
point ``R`` is mapped back to the object's rest frame exactly for uniform motion,
``q = L^-1 C^-1 (R + beta |R - camera| - c0)`` (``c0`` the box centre at the camera event,
``L`` the object's rotation and scale, ``C`` the contraction): ``R`` takes the velocity of the
smallest box holding ``q`` (grown by a margin), and as its rest normal the normal of the box face
nearest ``q``, turned toward the emitter (exact for flat and box-shaped receivers; measured in
the docs for the test's panel); in no box ``R`` is taken at rest with ``c_p = 1`` (its normal
unknown). The values are node inputs the sync writes
(:func:`receiver_values`); the nodes are rebuilt only when the number of moving objects changes.

SVM cannot multiply a closure by a number: a Mix Shader (its factor clamped to [0, 1]) with
``F / 8`` on the surface, added to itself three times (Cycles sums the weights of a closure
reached twice), gives ``F`` up to :data:`MAX_FACTOR`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...physics import bounce
from ..common import names
from ..common.nodes import Group, Literal, Node, fmath, group_node, vmath

if TYPE_CHECKING:
    from collections.abc import Sequence

RECEIVER = names.BOUNCE_RECEIVER_GROUP
FACTOR = names.BOUNCE_FACTOR_GROUP
DOUBLINGS = 3
MAX_FACTOR = 2.0**DOUBLINGS  # the largest F the closure scaling reaches (J alone is capped at 4)
FAR = 1.0e30  # "no box yet": any box is smaller
TINY = 1.0e-12
MAX_COSINE_RATIO = bounce.MAX_COSINE_RATIO

RECEIVER_INPUTS = ("Origin", "Beta", "Row X", "Row Y", "Row Z", "Normal X", "Normal Y", "Normal Z", "Half")
RECEIVER_FLOATS = ("Grow", "Volume")


def _vector_input(name: str) -> tuple:
    return (name, "NodeSocketVector", (0.0, 0.0, 0.0))


def receiver_group() -> Group:
    """One moving object's box: whether ``R`` lies in it (smaller than the best so far), and then
    its velocity and the rest normal of the face nearest ``R`` (world axes), chained."""
    nodes = {
        "moved": vmath("SCALE", "group.Beta", scale="group.Distance"),
        "advanced": vmath("ADD", "group.R", "moved"),
        "offset": vmath("SUBTRACT", "advanced", "group.Origin"),
        "qx": vmath("DOT_PRODUCT", "offset", "group.Row X"),
        "qy": vmath("DOT_PRODUCT", "offset", "group.Row Y"),
        "qz": vmath("DOT_PRODUCT", "offset", "group.Row Z"),
        "q": Node("ShaderNodeCombineXYZ", {0: "qx.Value", 1: "qy.Value", 2: "qz.Value"}),
        "size": vmath("ABSOLUTE", "q"),
        "gaps": vmath("SUBTRACT", "group.Half", "size"),  # distance inside each pair of faces
        "gap": Node("ShaderNodeSeparateXYZ", {0: "gaps"}),
        "gap_xy": fmath("MINIMUM", "gap.X", "gap.Y"),
        "nearest": fmath("MINIMUM", "gap_xy", "gap.Z"),
        "depth": fmath("ADD", "nearest", "group.Grow"),
        "inside": fmath("GREATER_THAN", "depth", 0.0),
        "smaller": fmath("LESS_THAN", "group.Volume", "group.Best Volume"),
        "take": fmath("MULTIPLY", "inside", "smaller"),
        # the nearest face (ties: their normals added, then normalised)
        "on_x": fmath("COMPARE", "gap.X", "nearest", 1.0e-6),
        "on_y": fmath("COMPARE", "gap.Y", "nearest", 1.0e-6),
        "on_z": fmath("COMPARE", "gap.Z", "nearest", 1.0e-6),
        "nx": vmath("SCALE", "group.Normal X", scale="on_x"),
        "ny": vmath("SCALE", "group.Normal Y", scale="on_y"),
        "nz": vmath("SCALE", "group.Normal Z", scale="on_z"),
        "nxy": vmath("ADD", "nx", "ny"),
        "nxyz": vmath("ADD", "nxy", "nz"),
        "face": vmath("NORMALIZE", "nxyz"),
        "volume": Node("ShaderNodeMix", {"Factor": "take", 2: "group.Best Volume", 3: "group.Volume"}),
        "beta": Node(
            "ShaderNodeMix", {"Factor": "take", 4: "group.Best Beta", 5: "group.Beta"}, {"data_type": "VECTOR"}
        ),
        "normal": Node("ShaderNodeMix", {"Factor": "take", 4: "group.Best Normal", 5: "face"}, {"data_type": "VECTOR"}),
    }
    inputs = (
        _vector_input("R"),
        ("Distance", "NodeSocketFloat", 0.0),
        *(_vector_input(name) for name in RECEIVER_INPUTS),
        ("Grow", "NodeSocketFloat", 0.0),
        ("Volume", "NodeSocketFloat", 0.0),
        ("Best Volume", "NodeSocketFloat", FAR),
        _vector_input("Best Beta"),
        _vector_input("Best Normal"),
    )
    outputs = (
        ("Best Volume", "NodeSocketFloat", "volume.Result"),
        ("Best Beta", "NodeSocketVector", "beta.Result"),
        ("Best Normal", "NodeSocketVector", "normal.Result"),
    )
    return Group(RECEIVER, "ShaderNodeTree", inputs, outputs, nodes)


def _merged(*parts: dict) -> dict:
    """Node dicts joined; a name used twice would silently replace a node (it did: ``ks_shift``)."""
    merged: dict = {}
    for part in parts:
        clash = merged.keys() & part.keys()
        if clash:
            raise ValueError(f"node names used twice: {sorted(clash)}")
        merged.update(part)
    return merged


def _rest_normal_nodes(prefix: str, normal: str, chat: str, beta: str, cb1: str, one_bb: str, bb_safe: str) -> dict:
    """``n ~ A^T N = C (N - chat (beta . N) / (1 + chat . beta))``: an apparent normal's rest normal
    (``cb1`` = 1 + chat . beta, ``one_bb`` = 1 - beta . beta, ``bb_safe`` = max(beta . beta, tiny))."""
    p = prefix
    return {
        f"{p}bn": vmath("DOT_PRODUCT", beta, normal),
        f"{p}along": fmath("DIVIDE", f"{p}bn.Value", cb1),
        f"{p}shift": vmath("SCALE", chat, scale=f"{p}along"),
        f"{p}v": vmath("SUBTRACT", normal, f"{p}shift"),
        # C v = v - (1 - sqrt(1 - bb)) (beta . v) / bb beta
        f"{p}root": fmath("SQRT", one_bb),
        f"{p}shrink": fmath("SUBTRACT", 1.0, f"{p}root"),
        f"{p}bv": vmath("DOT_PRODUCT", beta, f"{p}v"),
        f"{p}bv_bb": fmath("DIVIDE", f"{p}bv.Value", bb_safe),
        f"{p}cut": fmath("MULTIPLY", f"{p}shrink", f"{p}bv_bb"),
        f"{p}cut_vector": vmath("SCALE", beta, scale=f"{p}cut"),
        f"{p}contracted": vmath("SUBTRACT", f"{p}v", f"{p}cut_vector"),
        f"{p}n": vmath("NORMALIZE", f"{p}contracted"),
    }


def factor_group() -> Group:
    """``Surface`` scaled by ``F`` on non-camera rays whose origin lies in a moving object's box
    (``Found``), unchanged elsewhere (the OSL shader's formulas, node for node)."""
    nodes = _merged(
        {
            "geometry": Node("ShaderNodeNewGeometry"),
            "path": Node("ShaderNodeLightPath"),
            "emitter": Node(
                "ShaderNodeAttribute",
                {},
                {"attribute_type": "GEOMETRY", "attribute_name": Literal(names.BETA_ATTRIBUTE)},
            ),
            "toward": vmath("SCALE", "geometry.Incoming", scale="path.Ray Length"),
            "R": vmath("ADD", "geometry.Position", "toward"),
            "bb_vec": vmath("DOT_PRODUCT", "emitter.Vector", "emitter.Vector"),
            "c2": fmath("SUBTRACT", 1.0, "bb_vec.Value"),
            "gs": fmath("INVERSE_SQRT", "c2"),
            # where R sees this point: its world line back to R's light cone (uniform motion)
            "from_camera": vmath("SUBTRACT", "geometry.Position", "group.Camera"),
            "tx": vmath("LENGTH", "from_camera"),
            "dt": fmath("SUBTRACT", "tx.Value", "group.Distance"),
            "moved": vmath("SCALE", "emitter.Vector", scale="dt"),
            "p": vmath("ADD", "geometry.Position", "moved"),
            "D": vmath("SUBTRACT", "R", "p"),
            "a": vmath("DOT_PRODUCT", "D", "emitter.Vector"),
            "q": vmath("DOT_PRODUCT", "D", "D"),
            "aa": fmath("MULTIPLY", "a.Value", "a.Value"),
            "disc": fmath("MULTIPLY_ADD", "c2", "q.Value", "aa"),
            "root": fmath("SQRT", "disc"),
            "root_a": fmath("SUBTRACT", "root", "a.Value"),
            "root_safe": fmath("MAXIMUM", "root_a", TINY),
            "tau": fmath("DIVIDE", "q.Value", "root_safe"),
            "back": vmath("SCALE", "emitter.Vector", scale="tau"),
            "source": vmath("SUBTRACT", "p", "back"),
            "k": vmath("NORMALIZE", "k_raw"),
            "k_raw": vmath("SUBTRACT", "R", "source"),
            "snap_raw": vmath("SUBTRACT", "R", "geometry.Position"),
            "dsnap": vmath("LENGTH", "snap_raw"),
            "ks": vmath("NORMALIZE", "snap_raw"),
            "chat": vmath("NORMALIZE", "from_camera"),
            "cb": vmath("DOT_PRODUCT", "chat", "emitter.Vector"),
            "cb1": fmath("ADD", "cb.Value", 1.0),
            "bb_safe": fmath("MAXIMUM", "bb_vec.Value", TINY),
        },
        _rest_normal_nodes("e_", "geometry.Normal", "chat", "emitter.Vector", "cb1", "c2", "bb_safe"),
        {
            # J: the rest element's solid angle at R physically over its snapshot image's
            "det_inv": fmath("MULTIPLY", "gs", "cb1"),
            "bn": vmath("DOT_PRODUCT", "emitter.Vector", "e_n"),
            "bn_bb": fmath("DIVIDE", "bn.Value", "bb_safe"),
            "gs1": fmath("SUBTRACT", "gs", 1.0),
            "stretch_s": fmath("MULTIPLY", "gs1", "bn_bb"),
            "stretch_v": vmath("SCALE", "emitter.Vector", scale="stretch_s"),
            "stretched": vmath("ADD", "e_n", "stretch_v"),
            "cks": vmath("DOT_PRODUCT", "chat", "ks"),
            "ks_shift": vmath("SCALE", "emitter.Vector", scale="cks.Value"),
            "ks_mapped": vmath("ADD", "ks", "ks_shift"),
            "snap_dot": vmath("DOT_PRODUCT", "stretched", "ks_mapped"),
            "snap": fmath("DIVIDE", "snap_dot.Value", "det_inv"),
            "faces": fmath("GREATER_THAN", "snap", 0.0),
            "snap_safe": fmath("MAXIMUM", "snap", TINY),
        },
        {
            # n . k' with k' = (k + ((g - 1) (beta . k) / bb - g) beta) / (g (1 - beta . k)), unit
            # (aberration into the emitter's frame): (n . k + (beta . k) stretch_s - g (beta . n)) / (g den)
            "nk": vmath("DOT_PRODUCT", "e_n", "k"),
            "nk_along": fmath("MULTIPLY_ADD", "bk.Value", "stretch_s", "nk.Value"),
            "g_bn": fmath("MULTIPLY", "gs", "bn.Value"),
            "nk_rest": fmath("SUBTRACT", "nk_along", "g_bn"),
            "g_den": fmath("MULTIPLY", "gs", "den"),
            "cos_k": fmath("DIVIDE", "nk_rest", "g_den"),
            "cos_rest": fmath("MAXIMUM", "cos_k", 0.0),
            "d2": fmath("MULTIPLY", "dsnap.Value", "dsnap.Value"),
            "tau2": fmath("MULTIPLY", "tau", "tau"),
            "j_num": fmath("MULTIPLY", "cos_rest", "d2"),
            "j_den": fmath("MULTIPLY", "tau2", "snap_safe"),
            "j_ratio": fmath("DIVIDE", "j_num", "j_den"),
            "j_capped": fmath("MINIMUM", "j_ratio", 4.0),
            "J": fmath("MULTIPLY", "j_capped", "faces"),
            # the emitter's searchlight along k instead of k_snap
            "bks": vmath("DOT_PRODUCT", "emitter.Vector", "ks"),
            "bk": vmath("DOT_PRODUCT", "emitter.Vector", "k"),
            "num": fmath("SUBTRACT", 1.0, "bks.Value"),
            "den": fmath("SUBTRACT", 1.0, "bk.Value"),
            "ratio": fmath("DIVIDE", "num", "den"),
            "searchlight": fmath("POWER", "ratio", 4.0),
            # the receiver's frame: D_p^2 and its cosine on its rest normal (turned toward this point)
            "bp2": vmath("DOT_PRODUCT", "group.Beta P", "group.Beta P"),
            "one_bp2": fmath("SUBTRACT", 1.0, "bp2.Value"),
            "gp": fmath("INVERSE_SQRT", "one_bp2"),
            "bpk": vmath("DOT_PRODUCT", "group.Beta P", "k"),
            "one_bpk": fmath("SUBTRACT", 1.0, "bpk.Value"),
            "Dp": fmath("MULTIPLY", "gp", "one_bpk"),
            "Dp2": fmath("MULTIPLY", "Dp", "Dp"),
            # its rest normal m turned along ks (away from this point): the snapshot's cosine ks . m,
            # the physical one k'_p . m = (k . m + ((gp - 1) (bp . k) / bp2 - gp) (bp . m)) / Dp
            "side": vmath("DOT_PRODUCT", "group.Receiver Normal", "ks"),
            "sign": fmath("SIGN", "side.Value"),
            "m": vmath("SCALE", "group.Receiver Normal", scale="sign"),
            "before": fmath("ABSOLUTE", "side.Value"),
            "km": vmath("DOT_PRODUCT", "k", "m"),
            "bm": vmath("DOT_PRODUCT", "group.Beta P", "m"),
            "gp1": fmath("SUBTRACT", "gp", 1.0),
            "bp2_safe": fmath("MAXIMUM", "bp2.Value", TINY),
            "gp1_bpk": fmath("MULTIPLY", "gp1", "bpk.Value"),
            "along_p": fmath("DIVIDE", "gp1_bpk", "bp2_safe"),
            "shift_p": fmath("SUBTRACT", "along_p", "gp"),
            "km_rest": fmath("MULTIPLY_ADD", "shift_p", "bm.Value", "km.Value"),
            "after": fmath("DIVIDE", "km_rest", "Dp"),
            "after_pos": fmath("MAXIMUM", "after", 0.0),
            "before_safe": fmath("MAXIMUM", "before", 1.0e-6),
            "cp_ratio": fmath("DIVIDE", "after_pos", "before_safe"),
            "cp_box": fmath("MINIMUM", "cp_ratio", MAX_COSINE_RATIO),  # physics/bounce.py's cap
            # no box holds R (a receiver at rest: Beta P = 0, normal unknown): c_p = 1
            "cp_1": fmath("SUBTRACT", "cp_box", 1.0),
            "cp": fmath("MULTIPLY_ADD", "group.Found", "cp_1", 1.0),
            "receiver": fmath("MULTIPLY", "Dp2", "cp"),
            "js": fmath("MULTIPLY", "J", "searchlight"),
            "F": fmath("MULTIPLY", "js", "receiver"),
            # applied on non-camera rays (from a moving object's box, or from a receiver at rest): 1 + use (F - 1)
            "not_camera": fmath("SUBTRACT", 1.0, "path.Is Camera Ray"),
            "travelled": fmath("GREATER_THAN", "path.Ray Length", 0.0),
            "use": fmath("MULTIPLY", "not_camera", "travelled"),
            "F1": fmath("SUBTRACT", "F", 1.0),
            "gain": fmath("MULTIPLY_ADD", "use", "F1", 1.0),
            "share": fmath("DIVIDE", "gain", MAX_FACTOR),
            "scaled": Node("ShaderNodeMixShader", {0: "share", 2: "group.Surface"}),
        },
    )
    previous = "scaled"
    for index in range(DOUBLINGS):  # F / 8 added to itself three times: F
        nodes[f"double{index}"] = Node("ShaderNodeAddShader", {0: previous, 1: previous})
        previous = f"double{index}"
    inputs = (
        ("Surface", "NodeSocketShader", None),
        _vector_input("Camera"),
        ("Distance", "NodeSocketFloat", 0.0),
        _vector_input("Beta P"),
        _vector_input("Receiver Normal"),
        ("Found", "NodeSocketFloat", 0.0),
    )
    return Group(FACTOR, "ShaderNodeTree", inputs, (("Surface", "NodeSocketShader", previous),), nodes)


def scene_group_spec(name: str, count: int) -> Group:
    """The scene's group: ``count`` receiver boxes chained, then the factor on ``Surface``."""
    nodes = {
        "geometry": Node("ShaderNodeNewGeometry"),
        "path": Node("ShaderNodeLightPath"),
        "toward": vmath("SCALE", "geometry.Incoming", scale="path.Ray Length"),
        "R": vmath("ADD", "geometry.Position", "toward"),
        "to_camera": vmath("SUBTRACT", "R", (0.0, 0.0, 0.0)),  # its second input: the camera (the sync writes it)
        "distance": vmath("LENGTH", "to_camera"),  # |R - camera|, shared by the boxes and the factor
    }
    previous = None
    for index in range(count):
        links = {"R": "R", "Distance": "distance.Value"}
        if previous is not None:
            links.update(
                {
                    "Best Volume": f"{previous}.Best Volume",
                    "Best Beta": f"{previous}.Best Beta",
                    "Best Normal": f"{previous}.Best Normal",
                }
            )
        previous = receiver_node_name(index)
        nodes[previous] = group_node(RECEIVER, links)
    found = {}
    if previous is not None:
        nodes["found"] = fmath("LESS_THAN", f"{previous}.Best Volume", FAR * 0.5)
        found = {"Beta P": f"{previous}.Best Beta", "Receiver Normal": f"{previous}.Best Normal", "Found": "found"}
    nodes["factor"] = group_node(FACTOR, {"Surface": "group.Surface", "Distance": "distance.Value", **found})
    shader = (("Surface", "NodeSocketShader", None),)
    return Group(name, "ShaderNodeTree", shader, (("Surface", "NodeSocketShader", "factor"),), nodes)


def receiver_node_name(index: int) -> str:
    return f"receiver {index}"


def receiver_values(
    camera: Sequence[float],
    centre: Sequence[float],
    beta: Sequence[float],
    matrix: np.ndarray,
    low: Sequence[float] | np.ndarray,
    high: Sequence[float] | np.ndarray,
    margin: float,
) -> dict[str, float | tuple[float, ...]]:
    """One receiver node's inputs: the box centre at the camera event ``c0 = centre + beta |centre -
    camera|`` (``centre`` where the camera sees it), the rows of ``L^-1 C^-1`` (``matrix``: the
    object's 3x3 world matrix ``L``), the faces' rest normals (rows of ``L^-1``, normalised), the
    half sizes, the margin and the box's world volume (the smaller box wins)."""
    b = np.asarray(beta, dtype=np.float64)
    centre_now = np.asarray(centre, dtype=np.float64) + b * float(np.linalg.norm(np.subtract(centre, camera)))
    inverse = np.linalg.inv(np.asarray(matrix, dtype=np.float64))
    speed_squared = float(b @ b)
    gamma = 1.0 / np.sqrt(1.0 - speed_squared)
    stretch = np.eye(3) + ((gamma - 1.0) / speed_squared * np.outer(b, b) if speed_squared > 0.0 else 0.0)
    rows = inverse @ stretch  # q = L^-1 C^-1 offset (C^-1 symmetric)
    size = np.subtract(high, low)
    grow = margin * float(size.max()) + 1.0e-4
    volume = abs(float(np.linalg.det(matrix))) * float(np.prod(size + 2.0 * grow))

    def vector(v: Sequence[float] | np.ndarray) -> tuple[float, ...]:
        return tuple(float(x) for x in v)

    values: dict[str, float | tuple[float, ...]] = {
        "Origin": vector(centre_now),
        "Beta": vector(b),
        "Half": vector(size / 2.0),
        "Grow": grow,
        "Volume": volume,
    }
    for axis, row, face in zip("XYZ", rows, inverse, strict=True):
        values[f"Row {axis}"] = vector(row)
        values[f"Normal {axis}"] = vector(face / np.linalg.norm(face))
    return values
