"""Issue 26: what the apparent-geometry modifier's node group must not do at every evaluation.

Attribute Statistic sorts every value of its attribute when its Min, Max, Range or Median is used
(its Sum, Mean and the count of values are sums): on a 2M-vertex mesh a sort at every frame step.
The group's verdicts (the edges' images, the keyframed retarded times found) are counts, read from
Sum. The speed itself is measured by ``benchmarks/keyframed_modifier_profile.py`` and
``benchmarks/artist_chain.py``, not here.
"""

import geometry_helpers as gh

SORTING_OUTPUTS = {"Min", "Max", "Range", "Median"}


def test_no_attribute_statistic_sorts(relativity_addon):
    group = gh.addon_module("geometry.modifier").ensure_node_group()
    statistics = [node for node in group.nodes if node.bl_idname == "GeometryNodeAttributeStatistic"]
    assert statistics  # the verdicts are there
    sorting = [
        (node.name, socket.name)
        for node in statistics
        for socket in node.outputs
        if socket.name in SORTING_OUTPUTS and socket.is_linked
    ]
    assert sorting == [], sorting
