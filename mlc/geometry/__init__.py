"""Closed-form kinematics of the mechanism parts: logic core, scissor levers, rotations.

Units: lengths in sigma (the muscle rest length), angles in radians.
"""
