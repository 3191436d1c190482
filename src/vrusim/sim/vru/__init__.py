"""VRU motion along prescribed paths: triggers, speed profiles."""
