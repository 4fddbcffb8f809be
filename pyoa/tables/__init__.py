"""Tables the samplers read: GF(q) arithmetic, the low-discrepancy sequences' bases and directions, the pmj02 sequences."""
