"""The C-space of a translating robot: convex C-obstacle pieces built stage by stage, the
grid broad phase, point and segment queries, clearance, queries without a C-space."""
