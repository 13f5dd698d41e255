"""The spaces built on the kernel: the translation C-space and its broad phase, the sliced
SE(2) C-space and its certified motions, car curves and their certified checks, exact
shortest paths, and queries without a C-space."""
