"""Physics core of the relativity add-on: numpy (and colour-science for spectra), never bpy.

Every relation is written down in ``docs/physics.md``; each function names its frame and sign
conventions in its docstring.
"""
