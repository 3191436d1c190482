"""Pure geometry on arrays: paths (lines, arcs, clothoids, polylines), path tables, rectangle-circle contact, TTC."""
