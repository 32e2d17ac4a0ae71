"""volumen.bench (see DESIGN.md section 1)."""
