"""The smallest dynamic scenario the reader, budget and hostile-input tests start from.

``DYNAMIC`` ends in ``[solve]`` so a test can append solve keys; ``BASE`` adds an empty
``[output]`` (nothing written). Tests derive their cases by ``str.replace`` on these texts.
"""

DYNAMIC = """\
[surface]
shape = "plane"
cells = 3

[material]
w10 = 1.0
w01 = 1.0

[boundary]
u0 = "clamped"
u1 = "clamped"

[[load]]
kind = "uniform"
force = [0.0, 0.0, -1.0]
profile = "step"

[solve]
kind = "dynamic"
t_end = 2.0
frames = 5
"""

BASE = DYNAMIC + """
[output]
formats = []
"""
