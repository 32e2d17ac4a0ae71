"""volumen.render.raster (see DESIGN.md section 1)."""
