"""What the user touches: the settings (props: Scene.relativity; objects: Object.relativity), the
operators (ops), the N-panel (panel) and presets (presets).
"""
