"""The benchmarks: lfqt against the peers on the same input in the same
run (bench_dc: the 2D triangulation, bench_insert: lfqt.insert)."""
TITLE = "Benchmarks"
