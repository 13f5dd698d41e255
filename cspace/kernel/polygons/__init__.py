"""Exact predicates and polygons: the input gate, orientation, normalisation, convexity,
hulls, half-planes, disks, rotations, packed pieces, chord polygons and convex decomposition."""
