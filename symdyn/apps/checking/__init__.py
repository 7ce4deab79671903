"""`symdyn check`: a student's answers against symdyn's derivation (`check`; at a state:
`check_state`; the difference explained: `check_explain`; intermediate steps: `check_steps`),
and the derivation's steps themselves (`steps`, printed by `steps_output` for `derive --steps`)."""
