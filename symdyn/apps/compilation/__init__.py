"""`symdyn.compile`: a robot's generated C built with the system compiler for this machine and
cached (`compile`, `build`, `cache`, `robot_key`; the batch library, built on the first batch call:
`batch_library`), its functions called one state or a batch at a
time, in threads (`calling`, `compiled_frames`), and M singular at run time (`singular`)."""
