// sim: physics of the machine and the measurement chain. See sim/*/ for the parts.
