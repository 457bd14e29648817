// daemon: eicald internals. See daemon/*/ for the parts.
