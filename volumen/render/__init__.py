"""volumen.render (see DESIGN.md section 1)."""
