"""Every name the add-on stores in a .blend: datablocks, node groups, attributes, AOVs,
ID-property keys and version stamps.

They are read back from files saved by earlier versions, so a value here never changes; a
new layout gets a new version stamp instead.
"""

from __future__ import annotations

# --- exact camera ---------------------------------------------------------------------------
SHADER_TEXT = "relativistic_camera.osl"  # text datablock holding the OSL camera shader
CLAMP_SAVED_KEY = "relativity_saved_clamping"  # on the scene: the user's Cycles clamps while applied
STAMP_SAVED_KEY = "relativity_saved_note"  # on the scene: the user's metadata note while the effect is applied
CAMERA_SAVED_STATE_KEY = "relativity_saved_state"  # on camera data while the OSL camera is applied

# --- apparent geometry ----------------------------------------------------------------------
GEOMETRY_GROUP = "Relativity Apparent Geometry"  # geometry-nodes group
GEOMETRY_MODIFIER = "Relativity Apparent Geometry"
GEOMETRY_GROUP_VERSION_KEY = "relativity_version"  # the geometry group's own (older) stamp key
# 2: adaptive tessellation (face codes at the end of the cache); 3: the closed form; 4: keyframed motion in
# the modifier; 5: Edges Proven Short; 7: one polynomial over the keyframed window (Polynomial); 8: its
# terms by multiply-adds, Polynomial One Step, the closed form's Folded; 9: the polynomial's start line and
# closed-form steps (Polynomial Start Offset/Slope, no Polynomial Rate), Observer Moving
GEOMETRY_GROUP_VERSION = 9
# the same modifier's group for meshes on the constant closed form whose edges' bound clears (node_group.LEAN_WHEN)
LEAN_GEOMETRY_GROUP = "Relativity Apparent Geometry (Closed Form)"
LEAN_GEOMETRY_GROUP_VERSION = 2  # 2: Folded
REST_ATTRIBUTE = "relativity_rest"  # tessellated rest positions, stored by the modifier
BETA_ATTRIBUTE = "relativity_beta"  # point velocity relative to the observer (fraction of c)
FACE_CODE_ATTRIBUTE = "relativity_subdivide"  # per face: 1 subdivided, 2 across the seam (the cache's last points)
EDGES_SHORT_ATTRIBUTE = "relativity_edges_short"  # per face, by the modifier: every edge's image within the tolerance
# per point of the cache (its first points, one per sample interval): keyframed motion's Catmull-Rom
# coefficients of f**0 .. f**3 as 4x4 affine maps of the rest position (geometry/keyframed.py)
MOTION_ATTRIBUTES = tuple(f"relativity_motion_{power}" for power in range(4))
WINDOW_OK_ATTRIBUTE = "relativity_window_ok"  # per face, by the modifier: every retarded time in its intervals
SEEN_ATTRIBUTE = "relativity_seen"  # apparent positions of the faces across the seam, inside the modifier
TESSELLATION_KEY = "relativity_tessellation"  # on the cache mesh: the face codes' level, count and CRC-32
TESSELLATION_WARNING_KEY = "relativity_tessellation_warning"  # on the cache mesh: edges still too bent
CACHE_PREFIX = "RelativityCache"  # cache mesh objects (not linked into any scene)
SIGNATURE_KEY = "relativity_signature"  # on the cache mesh: inputs of the last update
ERROR_KEY = "relativity_error"  # on the cache mesh: why the last handler update failed
DEPTH_KEY = "relativity_depth"  # on the cache mesh: farthest depth in the camera's view (scene units)
WARNING_KEY = "relativity_warning"  # on the cache mesh: what the last update drew that is not the motion
OWNER_KEY = "relativity_owner"  # on the cache mesh: the name of the object it serves
BAKE_PREFIX = "RelativityBake"  # deformation bake meshes
BAKE_KEY = "relativity_bake"  # on the cache mesh: name of the bake mesh and its time grid
BAKE_ORIGINS_KEY = "origins"  # in the BAKE_KEY record: the object's origin at each sample (x, y, z, ...)
MOTION_BAKE_KEY = "relativity_motion_bake"  # on the cache mesh: baked world matrices

# --- Doppler colour: materials --------------------------------------------------------------
MATERIAL_ATTACHED_KEY = "relativity_doppler_nodes"  # on materials and worlds: inserted nodes
MATERIAL_NODE_PREFIX = "Relativity Doppler"
# custom property on objects with a blackbody temperature while Doppler colour is applied, read by
# an Object Attribute node inside shared node groups (a plain property: the file renders alone)
OBJECT_TEMPERATURE_PROPERTY = "relativity_blackbody_temperature"
SETTINGS_GROUP = "Relativity Settings"
DOPPLER_FACTOR_GROUP = "Relativity Doppler Factor"
GAMUT_MAP_GROUP = "Relativity Gamut Map"
DOPPLER_MATRIX_GROUP = "Relativity Doppler Matrix"
BLACKBODY_SHIFT_GROUP = "Relativity Blackbody Shift"
DOPPLER_COLOUR_GROUP = "Relativity Doppler Colour"
DOPPLER_AOV_GROUP = "Relativity Doppler AOV"
SPECTRAL_COLOUR_GROUP = "Relativity Spectral Colour"
SHADER_GROUPS_VERSION = 10  # 3: spectral passes, blackbodies shifted for camera rays only; 4: emitter D_s^4;
# 5: volumes in spectral passes; 6: the coverage AOV; 7: temperature grids in the volume group;
# 8: temperature grids in the spectral passes; 9: the emitter's D_s^4 on every ray behind the exact camera;
# 10: the bolometric rule through the Principled Volume's own Temperature and Tint
GROUP_VERSION_KEY = "relativity_group_version"  # on shader and compositor groups

# --- Doppler colour: compositor (exact camera) ----------------------------------------------
COMPOSITOR_GROUP = "Relativity Doppler Compositor"
COMPOSITOR_GAMUT_MAP_GROUP = "Relativity Gamut Map (Compositor)"
COMPOSITOR_GROUPS_VERSION = 8  # 4: the LUT read as two nearest texels (4.5's Map UV has no bilinear);
# 5: ln D over the coverage AOV; 6: the samples without AOV take ln D from the world-direction image;
# 7: the light groups' passes through their own tables; 8: the observed light group (its reflectance shift)
COMPOSITOR_SCENE_TREE = "Relativity Compositing"  # created when the scene has no compositor
COMPOSITOR_SAVED_KEY = "relativity_compositor_saved"  # on the scene: what was inserted where
LOG_DOPPLER_AOV = "relativity_log_doppler"  # ln D at the first camera hit
COVERAGE_AOV = "relativity_coverage"  # 1 with it: the pixel's share of samples that wrote ln D
COLOUR_DONE_AOV = "relativity_colour_done"  # 1 where a material already shifted the colour
WORLD_DOPPLER_IMAGE = "Relativity World Doppler"  # ln D of each pixel centre's direction (world_doppler)

# --- spectral mode -------------------------------------------------------------------------
SPECTRAL_IMAGE = "Relativity Spectral Render"  # the picture the spectral render makes

# --- lookup tables --------------------------------------------------------------------------
DOPPLER_LUT_IMAGE = "Relativity Doppler Matrix LUT"
BLACKBODY_LUT_IMAGE = "Relativity Blackbody LUT"
# The fast mode's light of blackbody lamps: one view-layer light group per lamp temperature (slot),
# its pass read through its own matrix table (light_groups.py, physics/illuminants.py).
LIT_GROUPS = ("Relativity Lit 1", "Relativity Lit 2")
ILLUMINANT_LUT_IMAGES = ("Relativity Illuminant LUT 1", "Relativity Illuminant LUT 2")
# The fast mode's light that the stand-in lamps of moving blackbody lights already shifted for the
# observer (shaders/relativistic_moving_lamp.osl): a light group whose pass the compositor shifts
# only by the reflectance's own shift (colour/compositing.py).
OBSERVED_LIGHT_GROUP = "Relativity Observed"
ILLUMINANT_KEY = "relativity_illuminant_k"  # on such an image: the illuminant it holds (K, 0 = white)
LIGHT_GROUPS_KEY = "relativity_light_groups"  # on the scene: the light groups it set, to give back
LUT_LAYOUT_KEY = "relativity_lut_layout"
LUT_LAYOUT_VERSION = 1

# --- moving lights --------------------------------------------------------------------------
MOVING_LIGHT_SHADER_TEXT = "relativistic_moving_light.osl"  # text datablock of the material OSL shader
MOVING_LIGHTS_GROUP = "Relativity Moving Lights"  # shader group: one script node per moving light
MOVING_LIGHTS_LIGHTS_KEY = "relativity_moving_lights"  # on that group: the light names of its script nodes
MOVING_LIGHTS_MATERIAL_KEY = "relativity_moving_lights"  # on materials: the inserted nodes and the old link
MOVING_LIGHT_NODE_PREFIX = "Relativity Moving Lights"
LIGHT_SAVED_KEY = "relativity_light_saved"  # on light objects: the user's hide_render while hidden
EMITTER_SAVED_KEY = "relativity_emitter_saved"  # on emitter meshes lighting the scene: the user's ray visibility
WORLD_SAMPLING_SAVED_KEY = "relativity_world_sampling_saved"  # on worlds: the user's Cycles light-sampling map
SHADING_SYSTEM_SAVED_KEY = "relativity_shading_system_saved"  # on the scene: the user's Open Shading Language

# --- lamps at rest lighting moving objects (eq. 18) -------------------------------------------
LAMP_DOPPLER_PREFIX = "Relativity Eq18"  # copies of lamps and their light-linking collections
LAMP_DOPPLER_KEY = "relativity_lamp_doppler"  # on the scene: what the stage added and changed
LAMP_DOPPLER_COPY_KEY = "relativity_lamp_copy"  # on a lamp copy: (lamp name, object name, index)
LAMP_STAND_IN_GROUP = "Relativity Eq18 Lamp"  # shader group in the copies' light trees: per-point D and direction
LAMP_STAND_IN_GROUP_VERSION = 3
REST_NORMAL_ATTRIBUTE = "relativity_rest_normal"  # corner normals of the rest shape (object space)
REST_NORMAL_KEY = "relativity_rest_normals"  # on the scene: the meshes given that attribute
REST_NORMAL_MESH_KEY = (
    "relativity_rest_normal_added"  # on such a mesh: the attribute is the add-on's (follows a rename)
)
REST_NORMAL_MATERIAL_KEY = "relativity_rest_normal_node"  # on materials: the inserted group node's name
REST_NORMAL_GROUP = "Relativity Rest Normal"  # shader group: rest-frame normal in world axes
REST_NORMAL_GROUP_VERSION = 2
BOUNCE_SHADER_TEXT = "relativistic_bounce.osl"  # text datablock of the bounce factor (lights/interreflection.py)
BOUNCE_TEXT_KEY = "relativity_bounce_text"  # on scenes: the name of the scene's own bounce text datablock
BOUNCE_MATERIAL_KEY = "relativity_bounce_node"  # on materials: the inserted script node and the old link
BOUNCE_NODE_NAME = "Relativity Bounce"  # the script node between a moving object's surface and its output
BOUNCE_GROUP_KEY = "relativity_bounce_group"  # on scenes (SVM): the name of the scene's own bounce node group
BOUNCE_SCENE_GROUP = "Relativity Bounce"  # that group's name: "<prefix> <scene name>" (lights/bounce_nodes.py)
BOUNCE_RECEIVER_GROUP = "Relativity Bounce Receiver"  # shader group: one moving object's box, velocity, face normal
BOUNCE_FACTOR_GROUP = "Relativity Bounce Factor"  # shader group: the bounce factor on a surface's closure
BOUNCE_GROUPS_VERSION = 2  # 2: the distance to the camera shared, receivers at rest corrected
MOVING_LAMP_SHADER_TEXT = "relativistic_moving_lamp.osl"  # text datablock of the stand-in lamps' light shader
MOVING_LAMP_PREFIX = "Relativity Lamp"  # stand-in objects "<prefix> <light> <index>", their light "<prefix> <light>"
MOVING_LAMP_INPUT_KEY = "relativity_lamp_"  # on a stand-in object: "<key><input>", its own shader inputs
SUN_DOPPLER_KEY = "relativity_sun_doppler"  # on a stand-in sun's light: D of the moving sun's light
SUN_REST_KEY = "relativity_sun_rest"  # on it too: the user's sun's colour, use_temperature, temperature
MOVING_LAMPS_KEY = "relativity_moving_lamps"  # on the scene: {light name: [stand-in object names]}
MOVING_PAIR_PREFIX = (
    "Relativity Pair"  # a moving light's lamps on one moving object: "<prefix> <light> on <object> <i>"
)
MOVING_PAIR_KEY = "relativity_moving_pairs"  # on the scene: those lamps, their light data and collections
MOVING_PAIR_COPY_KEY = "relativity_moving_pair"  # on such a lamp: (light name, object name, index)

# --- directly visible lamps (exact camera) ----------------------------------------------------
LAMP_FACE_PREFIX = "Relativity Lamp Face"  # emitter meshes (objects, meshes, materials): "<prefix> <light>"
LAMP_FACES_KEY = "relativity_lamp_faces"  # on the scene: {light object name: face object name}
LAMP_FACE_SAVED_KEY = "relativity_lamp_face_saved"  # on light objects: the user's visible_camera
VOLUME_BLACKBODY_GROUP = "Relativity Volume Blackbody"  # shader group: camera-ray emission of a blackbody volume
VOLUME_BLACKBODY_NODE_PREFIX = "Relativity Volume"  # nodes it inserts in a volume material
# in a material whose volume blackbody sits in a shared node group: the boundary marking its pixels done
VOLUME_GROUPED_BOUNDARY_NODE = "Relativity Volume Grouped Boundary"
VOLUME_COLOUR_GROUP = "Relativity Spectral Volume Colour"  # shader group: a volume colour, spectral in the passes
VOLUME_COLOUR_NODE_PREFIX = "Relativity Spectral Volume"  # its nodes in front of volume colour inputs

# --- Bake for Render Anywhere (pipeline/bake.py) -------------------------------------------------
BAKE_RECORD_KEY = "relativity_render_anywhere"  # on the scene: the baked frames, F-curves, actions, sequences
BAKE_ACTION_PREFIX = "Relativity Bake"  # actions the bake made for datablocks that had none
BAKE_IMAGE_SUFFIX = " (baked)"  # the image sequence standing for a per-frame image
BAKE_SCRATCH_IMAGE = "Relativity Bake Scratch"  # writes the sequence's files, removed at once
BAKE_FOLDER_SUFFIX = "_relativity_bake"  # the folder beside the .blend holding the sequences
# Apparent Geometry baked (geometry/playback.py): each frame's evaluated mesh, played back by frame
PLAYBACK_GROUP = "Relativity Baked Geometry"  # geometry-nodes group: the frame's mesh of a collection
PLAYBACK_GROUP_VERSION_KEY = "relativity_playback_version"
PLAYBACK_GROUP_VERSION = 1
PLAYBACK_MODIFIER = "Relativity Baked Geometry"  # the modifier playing it, after the apparent geometry's
PLAYBACK_PREFIX = "Relativity Baked"  # "<prefix> <object>": the collection; "<prefix> NNNNNN <object>": a frame

# Objects moving with the camera (camera/cockpit.py): a scene of their copies rendered at rest and
# laid over the relativistic render in the compositor.
COCKPIT_PREFIX = "Relativity Cockpit"  # the cockpit scene "<prefix> <scene>", its camera, its nodes
COCKPIT_KEY = "relativity_cockpit"  # on the scene: what the stage added and changed
COCKPIT_HIDDEN_KEY = "relativity_cockpit_hidden"  # on an object moving with the camera: the user's hide_render
COCKPIT_COPY_KEY = "relativity_cockpit_copy"  # on a copy in the cockpit scene: the original object's name
# The cockpit's sky (colour/cockpit_sky.py): a copy of the scene's world as the moving camera sees it
COCKPIT_SKY_KEY = "relativity_cockpit_sky"  # on the scene: the sky world's name and the world it copies
COCKPIT_SKY_PREFIX = "Relativity Cockpit Sky"  # the world "<prefix> <scene>", its nodes
COCKPIT_SKY_GROUP = "Relativity Cockpit Sky"  # shader group: camera-frame direction -> scene direction, ln D
COCKPIT_SKY_COLOUR_GROUP = "Relativity Cockpit Sky Colour"  # shader group: a colour as the moving camera sees it
COCKPIT_SKY_GROUPS_VERSION = 1
# The scene's lamps on the cockpit (lights/cockpit_lamps.py): their copies in the cockpit scene
COCKPIT_LAMPS_KEY = "relativity_cockpit_lamps"  # on the scene: {lamp name: its copy's name}
COCKPIT_LAMP_PREFIX = "Relativity Cockpit Lamp"  # the copies (objects and lights): "<prefix> <lamp>"
