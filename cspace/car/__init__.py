"""Car-like robots: Dubins and Reeds-Shepp curves and their certified checks over the SE(2)
C-space (CarCSpace), clearance along the curves."""
