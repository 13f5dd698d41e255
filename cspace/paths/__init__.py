"""Exact shortest paths in a free space: visibility, triangle meshes and channels of free
space, A*, exact path checks, the narrowest gap along a path."""
