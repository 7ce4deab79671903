"""`symdyn simulate`: a robot's motion under given torques or a tracking controller, stepped in C
(`simulate`, `stepping`; a floating base on SE(3): `floating_stepping`; closed loops:
`loop_simulate`), computed-torque control (`control`), and the trajectory with its plot and its
CSV, written in C too (`trajectory`, `csv_format`)."""
