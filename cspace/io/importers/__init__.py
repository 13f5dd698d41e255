"""Importers of other formats into scenarios: ROS occupancy maps (tracing blocked cells),
OMPL.app problems with COLLADA meshes (guarded), and the record of an import."""
