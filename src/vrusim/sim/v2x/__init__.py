"""V2X: roadside-unit messages, the ideal channel, the realistic channel and its compiled kernels."""
