"""Physics of a model: the energies, behind one interface (:mod:`.formulation`).

``parametric`` (the paper's model, Kronecker Gram matrices in :mod:`splinedeform.assembly`)
measures lengths and areas in the parameters; ``intrinsic`` (:mod:`.intrinsic`) measures
them on the initial surface, so the answer does not depend on how the surface was drawn;
both are the plate under tension of :mod:`.plate`. ``shell`` is the Kirchhoff–Love shell
(:mod:`.shell`, :mod:`.shell_formulation`). :class:`splinedeform.Model` serves all three.
"""

PHYSICS = ("parametric", "intrinsic")
"""The plate's physics (the shell has its own material and :class:`splinedeform.ShellModel`)."""
