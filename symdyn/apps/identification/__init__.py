"""`symdyn identify` and `symdyn excite`: the base parameters from a measured log (`identify`;
its logs: `measurements`, `measurements_binary`, pandas' CSV parser `csv_read`; the incremental
QR: `least_squares`) and exciting trajectories to measure (`excite`)."""
