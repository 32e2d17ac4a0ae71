"""volumen.render.raycast (see DESIGN.md section 1)."""
