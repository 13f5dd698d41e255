"""Input and output of scenes: the TOML scenario schema and loader, and the importers
(occupancy-grid maps, OMPL.app problems). Built on the kernel only."""
