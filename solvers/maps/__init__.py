"""The capability maps' compiled kernels: sampling, chain kinematics, voxel statistics."""
