/* zsobol: pbrt-v4's ZSobolSampler (filled in with the sampler). */
