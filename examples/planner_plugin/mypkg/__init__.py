"""mypkg: a user's own vrusim planners (the worked example of docs/planners.md)."""
