"""The C-space of a rotating robot: angle slabs of translation C-spaces, certified SE(2)
motions and poses, the slab graph, the exact planner and its proofs, path clearance."""
