"""The numerics of one resolver tick: the problem, its stages, the kernels and the report."""
