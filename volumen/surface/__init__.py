"""volumen.surface (see DESIGN.md section 1)."""
