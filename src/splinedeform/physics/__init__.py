"""Physics that belongs to the surface: energies measured with its first fundamental form.

``parametric`` (the paper's model, Kronecker Gram matrices in :mod:`splinedeform.model`)
measures lengths and areas in the parameters; ``intrinsic`` (:mod:`.intrinsic`) measures
them on the initial surface, so the answer does not depend on how the surface was drawn.
"""

PHYSICS = ("parametric", "intrinsic")
