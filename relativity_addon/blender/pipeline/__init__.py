"""Apply, sync and remove the effect (effect, through the stages listed in stages), the handler table
(handlers), the spectral mode's passes (spectral_render) and the physics in each frame's metadata
(metadata).
"""
