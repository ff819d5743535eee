"""A gear pair with a cracked pinion tooth and a pinion that runs out (issue 28): shaft-order terms of the model.

The paper's one-stage pair (Eqs. 1-2) with tooth counts, 20 on the pinion (gear 1, driven by M1) and 53 on the
wheel; tooth 7 of the pinion has a crack that takes the fraction q of its pair's stiffness while it is in mesh,
and the pinion's eccentricity adds a transmission error e_r cos(phi/20 + theta_r). Both repeat once per pinion
revolution, so the model's period is 20 mesh periods (``gearsym derive cracked_pair``: the window of the crack in
k(tau), the run-out in g's argument), on which its spectra, sweeps, Poincare sections and orbits run.
"""
from gearsym import Drivetrain, Eccentricity, Gear, Harmonic, Mesh, ToothFault, Torque

model = Drivetrain("cracked_pair", title="One-stage pair, 20/53 teeth, a cracked pinion tooth and pinion run-out")
pinion = model.add(Gear("gear1", inertia="I1", base_radius="r1", teeth=20))
wheel = model.add(Gear("gear2", inertia="I2", base_radius="r2", teeth=53))
model.add(Mesh("mesh", pinion, wheel, stiffness="kZ", damping="cZ", backlash="eta"))
model.add(Torque("M1", on=pinion, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M2", on=wheel, mean="M2", load=True))
model.add(ToothFault("crack", pinion, tooth=7, depth="q"))
model.add(Eccentricity("runout", pinion, amplitude="e_r", phase="theta_r"))
model.set_defaults(omega=1.5, zeta=0.08, B0=1.0, B1=4.0, Theta=0.0, eta=10.0, k_a=0.2, q=0.3, e_r=0.2,
                   theta_r=0.0)
model.set_initial_state(x=-2.0, v=-0.5)
model.describe(
    q="fraction of the stiffness of the pinion's tooth 7 that its crack takes away (0: healthy)",
    e_r="run-out of the pinion: amplitude of its transmission error, in the length unit of x",
    theta_r="phase of the pinion's run-out at tau = 0",
)
