"""Pure numerical kernels of rrc-pin: numpy and QP backends only (no Pinocchio, no files)."""
