"""Doppler colour and the searchlight: the materials' Doppler colour group (materials, doppler_colour),
the spectral passes' node group (spectral_nodes), the tables as images (lut_images), the compositor
stage (compositing), the fast mode's light groups (light_groups), volumes (volumes) and Blender's
World (world_colour, world_doppler, world_sampling).
"""
