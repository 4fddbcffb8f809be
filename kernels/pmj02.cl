/* pmj02: progressive multi-jittered (0,2) sequences (filled in with the sampler). */
