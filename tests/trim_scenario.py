"""A trimmed plate scenario in parts: the surface with its trim table, the clamped rim
loop, and the plate's material, load and static solve."""

HEAD = """
[surface]
shape = "plane"
cells = 10
knots = "uniform"
[surface.trim]
"""
RIM = """[[surface.trim.loops]]
name = "rim"
circle = { centre = [0.5, 0.5], radius = 0.4 }
edge = "clamped"
"""
TAIL = """[material]
w20 = 1.0
w11 = 1.0
w02 = 1.0
[[load]]
kind = "uniform"
force = [0, 0, 1]
[solve]
kind = "static"
"""

WINDOW = """[[surface.trim.loops]]
polygon = [[0.4, 0.4], [0.6, 0.4], [0.6, 0.6], [0.4, 0.6]]
"""

#: a disc with a square window cut from a plane, held on its rim (docs/trim.md)
TRIMMED = HEAD + RIM + WINDOW + TAIL
