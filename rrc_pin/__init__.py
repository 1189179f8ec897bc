"""rrc-pin: Pinocchio-backed resolved-rate control of robot arms."""
