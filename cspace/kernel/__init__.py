"""The exact kernel: predicates, convex polygons, hulls, Minkowski sums (the k-way merge),
half-planes and erosion, GJK/EPA, decomposition, non-convex sums, packed pieces, rotations
and slab hulls. numpy + shapely only; imports nothing else of cspace."""
