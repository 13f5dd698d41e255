"""Minkowski sums: the k-way angular merge (scalar and sorted routes, certified), batched
pairwise sums, convolution cycles and non-convex sums, checked unions, safety margins."""
