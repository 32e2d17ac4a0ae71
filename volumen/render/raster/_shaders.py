"""Shader programs from the ``.glsl`` files shipped in ``volumen/render/raster/shaders``.

One file per program, in the moderngl-window layout::

    #if defined VERTEX_SHADER
    ...
    #elif defined FRAGMENT_SHADER
    ...
    #endif

The files carry no ``#version`` line: the same files compile as desktop GLSL 3.30 core (moderngl, this
module's :func:`program`) and as GLSL ES 3.00 (WebGL2: the browser viewer of ``volumen.web``, which fetches
the sources :func:`stage_parts` writes). A stage's source is::

    #version 330 core | #version 300 es     (DIALECTS)
    #define VERTEX_SHADER | FRAGMENT_SHADER
    #define NAME value ...                  (the variant's defines)
    preamble.glsl                           (precision statements under GL_ES)
    #line 1
    the program's file

A variant is the same file compiled with other ``#define`` lines. A line ``#include "name.glsl"`` is replaced
by that file of the same folder (shared code such as ``lighting.glsl``, written once). The shader files are the
``.glsl`` files of the folder (:data:`SHADER_FILES`, found there: a new file needs no list to be added to).
Sources are read once (``importlib.resources``) and each (context, file, defines) program is compiled once and
cached.
"""

from __future__ import annotations

import functools
from importlib import resources

__all__ = ["shader_source", "stage_parts", "stage_source", "program", "glsl_files", "SHADER_FILES", "DIALECTS",
           "STAGES"]


def glsl_files(folder) -> tuple[str, ...]:
    """The names (without the suffix) of the ``.glsl`` files in ``folder`` (a path or an
    ``importlib.resources`` traversable), sorted."""
    return tuple(sorted(f.name.removesuffix(".glsl") for f in folder.iterdir()
                        if f.name.endswith(".glsl") and f.is_file()))


#: the shader files of the package (without the ``.glsl`` suffix): the ``.glsl`` files of its ``shaders`` folder
SHADER_FILES = glsl_files(resources.files(__package__).joinpath("shaders"))
#: dialect -> its #version line: desktop OpenGL 3.3 core, and WebGL2 (OpenGL ES 3.0)
DIALECTS = {"gl330": "#version 330 core", "es300": "#version 300 es"}
#: stage -> the macro its source is compiled with
STAGES = {"vertex": "VERTEX_SHADER", "fragment": "FRAGMENT_SHADER"}

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
            out += ["#line 1", _expand(shader_source(name)), f"#line {n + 1}"]
        else:
            out.append(line)
    return "\n".join(out)


@functools.cache
def stage_parts(name: str, stage: str, dialect: str = "gl330") -> tuple[str, str]:
    """``(head, body)`` of one stage of program ``name``: the variant's ``#define`` lines go between them.

    ``head`` is the dialect's ``#version`` line and the stage's macro; ``body`` the preamble and the
    program's file with its includes expanded, line numbers of compiler messages kept equal to the files'.
    """
    if dialect not in DIALECTS:
        raise ValueError(f"unknown GLSL dialect {dialect!r}; valid: {', '.join(DIALECTS)}")
    if stage not in STAGES:
        raise ValueError(f"unknown shader stage {stage!r}; valid: {', '.join(STAGES)}")
    source = shader_source(name)
    if source.startswith("#version"):
        raise ValueError(f"{name}.glsl must not start with a #version line: the dialect's is put before it")
    head = f"{DIALECTS[dialect]}\n#define {STAGES[stage]}"
    return head, f"{shader_source('preamble')}\n#line 1\n{_expand(source)}"


def stage_source(name: str, stage: str, defines: dict | None = None, dialect: str = "gl330") -> str:
    """The whole source of one stage of ``name`` with ``defines`` (``{NAME: value or ""}``)."""
    head, body = stage_parts(name, stage, dialect)
    lines = [f"#define {k} {v}".rstrip() for k, v in sorted((str(k), str(v)) for k, v in (defines or {}).items())]
    return "\n".join([head, *lines, body])


def program(ctx, name: str, defines: dict | None = None):
    """The compiled moderngl program of ``name`` with ``defines`` (``{NAME: value or ""}``), cached."""
    key_defs = tuple(sorted((str(k), str(v)) for k, v in (defines or {}).items()))
    key = (id(ctx), name, key_defs)
    prog = _programs.get(key)
    if prog is None:
        d = dict(key_defs)
        prog = ctx.program(vertex_shader=stage_source(name, "vertex", d),
                           fragment_shader=stage_source(name, "fragment", d))
        _programs[key] = prog
    return prog
