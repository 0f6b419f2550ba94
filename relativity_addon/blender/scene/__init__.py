"""The read side: everything the render paths need to know about a scene, read once into the frozen
``Snapshot`` (snapshot), from the settings, the camera, keyframes (animation), blackbody sources
(sources, grouped_colours), the lamps' temperatures (illuminants), emitting meshes that light the
scene (emitting_meshes) and the traveller's clock (traveller). Imports no stage.
"""
