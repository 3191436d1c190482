"""A test case as data: the pydantic schema, YAML reading, strict types, V2X channel specs, routes, score profiles."""
