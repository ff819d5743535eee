from gearsym import Drivetrain, Gear, Harmonic, Mesh, Torque

model = Drivetrain("spur_pair", title="Spur gear pair in physical units")
pinion = model.add(Gear("pinion", inertia="I1", base_radius="r1", teeth=28, speed="speed"))
wheel = model.add(Gear("wheel", inertia="I2", base_radius="r2", teeth=28))
model.add(Mesh("mesh", pinion, wheel, stiffness="kZ", damping="cZ", backlash="eta"))
model.add(Torque("M1", on=pinion, mean="M1", harmonics=(Harmonic("M1a", phase="Theta", group="B1"),)))
model.add(Torque("M2", on=wheel, mean="M2", load=True))
model.set_physical(I1="2.0e-3 kg*m^2", I2="2.0e-3 kg*m^2", r1="41.8 mm", r2="41.8 mm", kZ="2e8 N/m",
                   cZ="500 N*s/m", eta="50 um", M1="70 N*m", M2="70 N*m", M1a="20 N*m", Theta=0, k_a=0.2,
                   speed="3000 rpm")
