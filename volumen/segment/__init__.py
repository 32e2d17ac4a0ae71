"""volumen.segment (see DESIGN.md section 1)."""
