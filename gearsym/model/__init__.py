"""Declaring drivetrains: components, parameters and the Lagrangian (pipeline step 1).

:mod:`.components` (Gear, Disk, Planet, Mesh, Shaft, Torque, Harmonic), :mod:`.drivetrain` (the
:class:`~.drivetrain.Drivetrain` they are added to), :mod:`.resolved` (every declaration checked, with its
kinematics), :mod:`.lagrangian` and :mod:`.planetary` (its bases), :mod:`.expressions`, :mod:`.formula` and
:mod:`.grammar` (what a user writes, read without running it), :mod:`.stiffness` (mesh stiffness shapes),
:mod:`.length_scale`. The modules are imported by name (the face, ``gearsym.Drivetrain`` ..., hands them on),
so that the light ones (the grammar, the length scale) never load SymPy.
"""
