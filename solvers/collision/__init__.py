"""The collision limit's compiled kernels: broad phase, narrow phase, damper rows."""
