"""What every layer uses and nothing of pyoa's: atomic files, units, progress bars, the host CPU, Dr.Jit's LLVM."""
