"""Apparent Geometry: each moving object's retarded positions (motion: world lines from the Motion
setting), written to cache meshes that a geometry-nodes modifier reads (apparent_meshes, modifier),
shape keys at other times (shape_keys) and the Bake Motion / Bake Deformation operators (bakes).
"""
