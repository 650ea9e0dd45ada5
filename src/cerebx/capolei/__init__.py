"""The cerebellar internal models of Capolei et al. (2020): an LWPR granular layer and plastic
PF-PC, PC-DCN, MF-DCN and IO-DCN synapses per joint and microcircuit, with the velocity PID they
correct (architectures I-IV as composite controllers)."""
