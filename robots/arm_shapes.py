"""Collision primitives of the built-in arms, per link in the link frame (m).

Written by ``benchmarks/fit_link_shapes.py`` from the ROS-Industrial collision meshes
of the same arms (``ros-industrial/abb_experimental``, Apache-2.0; no mesh is kept
here): each link's primitives enclose its mesh with at least 1 mm to spare.
``tests/robots/test_robots_enclosure.py`` checks them against points measured on the
meshes. Sizes: box (x, y, z) edge lengths; cylinder (radius, length) along ``axis``.
"""

from __future__ import annotations

#: (link, kind, size, xyz of the centre in the link frame, cylinder axis)
Primitive = tuple[str, str, tuple[float, ...], tuple[float, float, float], str]

#: model -> its primitives, link by link
LINK_PRIMITIVES: dict[str, tuple[Primitive, ...]] = {
    "abb_irb1600_10_145": (
        ("base_link", "box", (0.432, 0.486, 0.152), (-0.168, 0, 0.075), "z"),
        ("base_link", "cylinder", (0.281, 0.174), (0, 0, 0.086), "z"),
        ("link_1", "box", (0.581, 0.359, 0.319), (0.0245, 0.0145, 0.2825), "z"),
        ("link_1", "cylinder", (0.161, 0.541), (0.0465, -0.008, 0.483), "x"),
        ("link_1", "box", (0.399, 0.238, 0.082), (0.0925, -0.023, 0.612), "z"),
        ("link_2", "box", (0.178, 0.137, 0.432), (0, -0.1855, 0.126), "z"),
        ("link_2", "box", (0.162, 0.134, 0.363), (-0.001, -0.172, 0.5205), "z"),
        ("link_2", "cylinder", (0.072, 0.113), (0, -0.1635, 0.7), "y"),
        ("link_3", "cylinder", (0.177, 0.266), (0, 0.029, 0), "y"),
        ("link_3", "box", (0.32, 0.283, 0.246), (0.033, 0.0205, -0.014), "z"),
        ("link_3", "box", (0.126, 0.198, 0.187), (0.253, 0.003, -0.0165), "z"),
        ("link_4", "box", (0.258, 0.128, 0.115), (0.142, 0, 0.0005), "z"),
        ("link_4", "cylinder", (0.058, 0.127), (0.3, -0.0005, 0), "y"),
        ("link_5", "cylinder", (0.044, 0.05), (0, 0, 0), "y"),
        ("link_6", "cylinder", (0.026, 0.068), (-0.032, 0, 0), "x"),
    ),
    "abb_irb2600_20_165": (
        ("base_link", "box", (0.138, 0.406, 0.205), (-0.333, 0, 0.1055), "z"),
        ("base_link", "cylinder", (0.259, 0.233), (-0.106, 0, 0.1155), "z"),
        ("base_link", "cylinder", (0.216, 0.233), (0.062, 0, 0.1155), "z"),
        ("link_1", "box", (0.496, 0.262, 0.457), (0.033, -0.021, -0.0645), "z"),
        ("link_1", "box", (0.393, 0.089, 0.405), (0.0575, 0.1515, -0.0705), "z"),
        ("link_1", "box", (0.258, 0.089, 0.286), (0.102, 0.2375, -0.044), "z"),
        ("link_2", "cylinder", (0.102, 0.102), (0, -0.174, 0), "y"),
        ("link_2", "box", (0.202, 0.152, 0.426), (0, -0.163, 0.211), "z"),
        ("link_2", "box", (0.171, 0.141, 0.351), (0.0025, -0.1695, 0.5965), "z"),
        ("link_3", "box", (0.292, 0.344, 0.355), (0.005, 0.02, 0.0615), "z"),
        ("link_3", "cylinder", (0.142, 0.325), (0.15, 0.001, 0.0735), "z"),
        ("link_3", "box", (0.07, 0.202, 0.229), (0.272, 0, 0.0955), "z"),
        ("link_4", "box", (0.528, 0.17, 0.156), (0.55, -0.004, 0), "z"),
        ("link_4", "cylinder", (0.078, 0.169), (0.795, -0.0045, 0), "y"),
        ("link_5", "cylinder", (0.06, 0.044), (0, 0, 0), "y"),
        ("link_6", "cylinder", (0.033, 0.037), (-0.0175, 0, 0), "x"),
    ),
    "abb_irb4600_60_205": (
        ("base_link", "box", (0.408, 0.518, 0.215), (-0.198, 0, 0.1065), "z"),
        ("base_link", "cylinder", (0.277, 0.183), (0, 0, 0.0905), "z"),
        ("link_1", "cylinder", (0.095, 0.424), (-0.171, 0, -0.114), "z"),
        ("link_1", "cylinder", (0.21, 0.488), (0, 0, -0.099), "z"),
        ("link_1", "cylinder", (0.3, 0.544), (0.088, 0.049, -0.076), "y"),
        ("link_2", "cylinder", (0.142, 0.157), (0, -0.1635, 0), "y"),
        ("link_2", "cylinder", (0.148, 0.548), (0, -0.158, 0.272), "z"),
        ("link_2", "cylinder", (0.132, 0.46), (0, -0.183, 0.773), "z"),
        ("link_3", "box", (0.349, 0.402, 0.477), (-0.0075, 0.05, 0.0945), "z"),
        ("link_3", "cylinder", (0.183, 0.402), (0.166, 0.039, 0.123), "z"),
        ("link_3", "box", (0.083, 0.271, 0.288), (0.3125, 0.0275, 0.145), "z"),
        ("link_4", "cylinder", (0.106, 0.222), (0.441, -0.001, 0), "x"),
        ("link_4", "box", (0.478, 0.231, 0.198), (0.788, 0.0025, 0), "z"),
        ("link_4", "cylinder", (0.109, 0.218), (0.96, 0, 0), "y"),
        ("link_5", "cylinder", (0.081, 0.135), (0, -0.0015, 0), "y"),
        ("link_6", "cylinder", (0.064, 0.072), (-0.035, 0, 0), "x"),
    ),
}
