"""Kinematics of a serial chain taken from the robot model: the chain between two links
(``chain``), forward kinematics (``fk``), Denavit-Hartenberg extraction (``dh``), numeric
Jacobians and their analysis (``jacobian``) and symbolic expressions (``symbolic``, sympy).

These modules import numpy at module level; nothing on the ``check`` path imports them.
"""
