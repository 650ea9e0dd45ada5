"""The spiking-network engine: topology from a network config, numba kernels over flat arrays, encoders and the
decoder."""
