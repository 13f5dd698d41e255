"""Angle slabs of a turning piece: slab hulls and inner sets, slab indexing and counts, the
inscribed disk."""
