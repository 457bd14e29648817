// drivers: Source backends, SPSC ring, run reader/writer. See drivers/*/ for the parts.
