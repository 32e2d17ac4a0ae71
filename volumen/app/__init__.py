"""volumen.app (see DESIGN.md section 1)."""
