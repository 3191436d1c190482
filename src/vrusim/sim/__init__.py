"""The models: ego dynamics, VRU motion, sensing (sector, occlusion, sensor model), V2X, observation, random numbers."""
