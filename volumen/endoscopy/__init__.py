"""volumen.endoscopy (see DESIGN.md section 1)."""
