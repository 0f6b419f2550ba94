"""The exact camera: the OSL camera of Gray et al. in the scene's camera (exact_camera) and Cycles'
sample clamping scaled by the searchlight while it renders (clamping).
"""
