// Put before every program, after the #version line and the variant's #defines (raster/_shaders.py): what
// differs between the two dialects the same files compile as, desktop GLSL 3.30 core (OpenGL, moderngl) and
// GLSL ES 3.00 (WebGL2, the browser viewer of volumen.web). GL_ES is predefined by ES compilers only.
#if defined GL_ES
// ES has no default precision for floats in fragment shaders nor for 3-D and integer samplers; highp
// everywhere: positions in voxels, depths in mm and the jitter hash need 32 bits.
precision highp float;
precision highp int;
precision highp sampler2D;
precision highp sampler3D;
precision highp usampler3D;
#endif
