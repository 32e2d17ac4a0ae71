"""Shader programs from the ``.glsl`` files shipped in ``volumen/render/raster/shaders``.

One file per program, in the moderngl-window layout::

    #version 330 core
    #if defined VERTEX_SHADER
    ...
    #elif defined FRAGMENT_SHADER
    ...
    #endif

A variant is the same file compiled with extra ``#define`` lines injected
after ``#version``. A line ``#include "name.glsl"`` is replaced by that file of
the same folder (shared code such as ``lighting.glsl``, written once). Sources are read once
(``importlib.resources``) and each (context, file, defines) program is compiled once and cached.
"""

from __future__ import annotations

import functools
from importlib import resources

__all__ = ["shader_source", "program", "SHADER_FILES"]

#: the shader files of the package (without the ``.glsl`` suffix)
SHADER_FILES = ("slicing", "mesh", "lighting", "raycast", "raycast_modes")

_programs: dict = {}


@functools.cache
def shader_source(name: str) -> str:
    """Text of ``shaders/<name>.glsl`` (read once)."""
    if name not in SHADER_FILES:
        raise ValueError(f"unknown shader {name!r}; valid: {', '.join(SHADER_FILES)}")
    return resources.files(__package__).joinpath("shaders", f"{name}.glsl").read_text(encoding="utf-8")


def _expand(source: str) -> str:
    out = []
    for n, line in enumerate(source.split("\n"), start=1):
        s = line.strip()
        if s.startswith("#include"):
            name = s.split('"')[1].removesuffix(".glsl")
            out += [_expand(shader_source(name)), f"#line {n + 2}"]
        else:
            out.append(line)
    return "\n".join(out)


def _stage(source: str, stage: str, defines: tuple[tuple[str, str], ...]) -> str:
    first, _, rest = source.partition("\n")
    if not first.startswith("#version"):
        raise ValueError("a shader file must start with its #version line")
    lines = [first, f"#define {stage}"] + [f"#define {k} {v}".rstrip() for k, v in defines]
    # keep line numbers of compiler messages equal to the file's
    return "\n".join(lines) + f"\n#line 2\n{_expand(rest)}"


def program(ctx, name: str, defines: dict | None = None):
    """The compiled moderngl program of ``name`` with ``defines`` (``{NAME: value or ""}``), cached."""
    key_defs = tuple(sorted((str(k), str(v)) for k, v in (defines or {}).items()))
    key = (id(ctx), name, key_defs)
    prog = _programs.get(key)
    if prog is None:
        src = shader_source(name)
        prog = ctx.program(vertex_shader=_stage(src, "VERTEX_SHADER", key_defs),
                           fragment_shader=_stage(src, "FRAGMENT_SHADER", key_defs))
        _programs[key] = prog
    return prog
