"""voiga performance benchmarks (``make bench`` / ``python3 -m bench``).

Every figure is a ratio measured within one run on the same machine; absolute seconds
are printed for reference only (the machines we use are noisy)."""
