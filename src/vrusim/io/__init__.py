"""File output shared by every layer: atomic write-then-rename."""
