"""The OMPL adapters: OMPL's import, planner names, set-up and seeds (:mod:`~planners.adapters.glue`),
the optimisation objectives, and one state-space adapter per kind of robot, each answering the
planning routine's questions (state space, validity, certified motions, verification, length):

- :mod:`~planners.adapters.translation`: a translating robot, poses (x, y);
- :mod:`~planners.adapters.se2`: a rotating robot, poses (x, y, theta), over the SE(2) C-space;
- :mod:`~planners.adapters.car`: Dubins and Reeds-Shepp cars over the same C-space;
- :mod:`~planners.adapters.frame`: what they share (OMPL's scaled frame, path verification, length).

Importing them does not import OMPL: it loads when a state space or validator is made.
"""
