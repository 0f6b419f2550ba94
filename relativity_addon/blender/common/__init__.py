"""Leaves every part of the glue may use: every name stored in a .blend (names), the declarative node-tree
builder (nodes), every call that differs between Blender 4.5 and 5.2 (compat), the re-entrancy guard
(busy), ray-visibility flags kept and given back (visibility), OSL compilation support (osl).
"""
