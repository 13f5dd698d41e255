"""Distances between convex polygons: GJK (float loop, exact decisions near contact) and EPA."""
