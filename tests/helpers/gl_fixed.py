"""A real OpenGL 2.1 fixed-function render through Mesa (PyOpenGL over EGL, surfaceless, into a
framebuffer object): ``glLightfv``, ``glMaterialfv``, ``glTexEnvi(GL_MODULATE)``,
``GL_LIGHT_MODEL_COLOR_CONTROL``. The oracle the textured pictures are held to: it shares no
code with the engine or the VTK drawing, only the mesh, the scene's numbers (in the
:func:`helpers.scenes.to_gl` form), the camera's two matrices and the image.

:func:`context` gives None with the reason when no GL context can be made (no PyOpenGL, no EGL
library, no Mesa driver), for the tests to skip with it.
"""

from __future__ import annotations

import ctypes
import os

import numpy as np

_STATE: dict = {}


def context() -> tuple[object | None, str]:
    """``(GL module, "")`` with a current compatibility-profile context, or ``(None, why)``."""
    if "gl" in _STATE or "why" in _STATE:
        return _STATE.get("gl"), _STATE.get("why", "")
    try:
        os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
        from OpenGL import EGL, GL
        from OpenGL.EGL.EXT.platform_base import eglGetPlatformDisplayEXT

        surfaceless = 0x31DD  # EGL_PLATFORM_SURFACELESS_MESA: no X server, no device file
        dpy = eglGetPlatformDisplayEXT(surfaceless, EGL.EGL_DEFAULT_DISPLAY, None)
        major, minor = EGL.EGLint(), EGL.EGLint()
        if not EGL.eglInitialize(dpy, ctypes.pointer(major), ctypes.pointer(minor)):
            raise RuntimeError("eglInitialize failed")
        config, count = EGL.EGLConfig(), EGL.EGLint()
        wanted = (EGL.EGLint * 3)(EGL.EGL_RENDERABLE_TYPE, EGL.EGL_OPENGL_BIT, EGL.EGL_NONE)
        EGL.eglChooseConfig(dpy, wanted, ctypes.pointer(config), 1, ctypes.pointer(count))
        EGL.eglBindAPI(EGL.EGL_OPENGL_API)
        ctx = EGL.eglCreateContext(dpy, config, EGL.EGL_NO_CONTEXT, None)
        if not EGL.eglMakeCurrent(dpy, EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE, ctx):
            raise RuntimeError("eglMakeCurrent failed")
        version = GL.glGetString(GL.GL_VERSION).decode()
        if "Compatibility" not in version and not version.startswith(("2.", "3.0")):
            raise RuntimeError(f"no fixed-function context (GL {version})")
        _STATE.update(gl=GL, egl=EGL, dpy=dpy, ctx=ctx, version=version)
    except Exception as exc:  # noqa: BLE001 - any failure means: no context here, say why
        _STATE["why"] = f"no OpenGL fixed-function context: {type(exc).__name__}: {exc}"
    return _STATE.get("gl"), _STATE.get("why", "")


def _rgba(rgb, alpha: float = 1.0) -> list[float]:
    return [float(c) for c in rgb] + [alpha]


def _column_major(matrix) -> np.ndarray:
    """A 4x4 row-major matrix (VTK's) as OpenGL's column-major 16 doubles."""
    return np.ascontiguousarray(np.asarray(matrix, np.float64).T.ravel())


def render(
    positions,
    normals,
    faces,
    gl_scene: dict,
    *,
    view,
    projection,
    size: tuple[int, int],
    two_sided: bool = False,
    separate: bool = False,
    image=None,
    st=None,
    clamp: bool = False,
) -> np.ndarray:
    """The fixed-function picture: (h, w, 4) uint8, rows top first, alpha 0 where nothing is
    drawn.

    positions, normals : (n, 3) the vertices as drawn (the renderer's frame); faces : (m, 3)
    gl_scene : :func:`helpers.scenes.to_gl`'s form; view, projection : 4x4 row-major (VTK's
        camera's model-view and projection matrices)
    separate : GL_SEPARATE_SPECULAR_COLOR (else GL_SINGLE_COLOR)
    image : (h, w, 3|4) uint8 texture, rows top first (None: no texture); st : (n, 2) its
        texture coordinates; clamp : GL_CLAMP_TO_EDGE (else GL_REPEAT); GL_NEAREST always
    """
    GL, why = context()
    if GL is None:
        raise RuntimeError(why)
    EGL = _STATE["egl"]  # VTK's own context may be current: make this one current again
    EGL.eglMakeCurrent(_STATE["dpy"], EGL.EGL_NO_SURFACE, EGL.EGL_NO_SURFACE, _STATE["ctx"])
    w, h = size
    fbo = GL.glGenFramebuffers(1)
    GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, fbo)
    colour, depth = GL.glGenRenderbuffers(2)
    GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, colour)
    GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_RGBA8, w, h)
    GL.glFramebufferRenderbuffer(
        GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0, GL.GL_RENDERBUFFER, colour
    )
    GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, depth)
    GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_DEPTH_COMPONENT24, w, h)
    GL.glFramebufferRenderbuffer(
        GL.GL_FRAMEBUFFER, GL.GL_DEPTH_ATTACHMENT, GL.GL_RENDERBUFFER, depth
    )
    texture = None
    try:
        GL.glViewport(0, 0, w, h)
        GL.glClearColor(0.0, 0.0, 0.0, 0.0)
        GL.glClear(GL.GL_COLOR_BUFFER_BIT | GL.GL_DEPTH_BUFFER_BIT)
        GL.glEnable(GL.GL_DEPTH_TEST)
        GL.glDisable(GL.GL_CULL_FACE)
        GL.glDisable(GL.GL_DITHER)
        GL.glShadeModel(GL.GL_SMOOTH)
        GL.glMatrixMode(GL.GL_PROJECTION)
        GL.glLoadMatrixd(_column_major(projection))
        GL.glMatrixMode(GL.GL_MODELVIEW)
        GL.glLoadMatrixd(_column_major(view))  # lights below are given in world coordinates
        GL.glEnable(GL.GL_LIGHTING)
        GL.glLightModelfv(GL.GL_LIGHT_MODEL_AMBIENT, _rgba(gl_scene["ambient"]))
        GL.glLightModeli(GL.GL_LIGHT_MODEL_LOCAL_VIEWER, int(bool(gl_scene["local_viewer"])))
        GL.glLightModeli(GL.GL_LIGHT_MODEL_TWO_SIDE, int(two_sided))
        control = GL.GL_SEPARATE_SPECULAR_COLOR if separate else GL.GL_SINGLE_COLOR
        GL.glLightModeli(GL.GL_LIGHT_MODEL_COLOR_CONTROL, control)
        m = gl_scene["material"]
        side = GL.GL_FRONT_AND_BACK
        GL.glMaterialfv(side, GL.GL_AMBIENT, _rgba(m["ambient"]))
        GL.glMaterialfv(side, GL.GL_DIFFUSE, _rgba(m["diffuse"]))
        GL.glMaterialfv(side, GL.GL_SPECULAR, _rgba(m["specular"]))
        GL.glMaterialfv(side, GL.GL_EMISSION, _rgba(m.get("emission", (0, 0, 0))))
        GL.glMaterialf(side, GL.GL_SHININESS, float(m["shininess"]))
        for i, light in enumerate(gl_scene["lights"]):
            li = GL.GL_LIGHT0 + i
            GL.glEnable(li)
            GL.glLightfv(li, GL.GL_AMBIENT, _rgba(light["ambient"]))
            GL.glLightfv(li, GL.GL_DIFFUSE, _rgba(light["diffuse"]))
            GL.glLightfv(li, GL.GL_SPECULAR, _rgba(light["specular"]))
            GL.glLightfv(li, GL.GL_POSITION, [float(c) for c in light["position"]])
            k0, k1, k2 = light["attenuation"]
            GL.glLightf(li, GL.GL_CONSTANT_ATTENUATION, float(k0))
            GL.glLightf(li, GL.GL_LINEAR_ATTENUATION, float(k1))
            GL.glLightf(li, GL.GL_QUADRATIC_ATTENUATION, float(k2))
            GL.glLightf(li, GL.GL_SPOT_CUTOFF, float(light["spot_cutoff"]))
            aim = light["spot_direction"] or (0.0, 0.0, -1.0)
            GL.glLightfv(li, GL.GL_SPOT_DIRECTION, [float(c) for c in aim])
            GL.glLightf(li, GL.GL_SPOT_EXPONENT, float(light["spot_exponent"]))
        GL.glEnableClientState(GL.GL_VERTEX_ARRAY)
        GL.glEnableClientState(GL.GL_NORMAL_ARRAY)
        p = np.ascontiguousarray(positions, np.float32)
        n = np.ascontiguousarray(normals, np.float32)
        GL.glVertexPointer(3, GL.GL_FLOAT, 0, p)
        GL.glNormalPointer(GL.GL_FLOAT, 0, n)
        if image is not None:
            rows = np.ascontiguousarray(np.asarray(image, np.uint8)[::-1])  # bottom row first
            if rows.shape[2] == 3:
                rows = np.concatenate([rows, np.full(rows.shape[:2] + (1,), 255, np.uint8)], 2)
            rows = np.ascontiguousarray(rows)
            texture = GL.glGenTextures(1)
            GL.glEnable(GL.GL_TEXTURE_2D)
            GL.glBindTexture(GL.GL_TEXTURE_2D, texture)
            GL.glPixelStorei(GL.GL_UNPACK_ALIGNMENT, 1)
            GL.glTexImage2D(
                GL.GL_TEXTURE_2D,
                0,
                GL.GL_RGBA8,
                rows.shape[1],
                rows.shape[0],
                0,
                GL.GL_RGBA,
                GL.GL_UNSIGNED_BYTE,
                rows,
            )
            for pname in (GL.GL_TEXTURE_MIN_FILTER, GL.GL_TEXTURE_MAG_FILTER):
                GL.glTexParameteri(GL.GL_TEXTURE_2D, pname, GL.GL_NEAREST)
            wrap = GL.GL_CLAMP_TO_EDGE if clamp else GL.GL_REPEAT
            GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_S, wrap)
            GL.glTexParameteri(GL.GL_TEXTURE_2D, GL.GL_TEXTURE_WRAP_T, wrap)
            GL.glTexEnvi(GL.GL_TEXTURE_ENV, GL.GL_TEXTURE_ENV_MODE, GL.GL_MODULATE)
            GL.glEnableClientState(GL.GL_TEXTURE_COORD_ARRAY)
            GL.glTexCoordPointer(2, GL.GL_FLOAT, 0, np.ascontiguousarray(st, np.float32))
        f = np.ascontiguousarray(faces, np.uint32).ravel()
        GL.glDrawElements(GL.GL_TRIANGLES, len(f), GL.GL_UNSIGNED_INT, f)
        GL.glFinish()
        error = GL.glGetError()
        if error:
            raise RuntimeError(f"OpenGL error {error:#x}")
        pixels = GL.glReadPixels(0, 0, w, h, GL.GL_RGBA, GL.GL_UNSIGNED_BYTE)
        out = np.frombuffer(pixels, np.uint8).reshape(h, w, 4)[::-1]
        return np.ascontiguousarray(out)
    finally:
        GL.glDisableClientState(GL.GL_TEXTURE_COORD_ARRAY)
        GL.glDisableClientState(GL.GL_VERTEX_ARRAY)
        GL.glDisableClientState(GL.GL_NORMAL_ARRAY)
        GL.glDisable(GL.GL_TEXTURE_2D)
        for i in range(8):
            GL.glDisable(GL.GL_LIGHT0 + i)
        if texture is not None:
            GL.glDeleteTextures([texture])
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, 0)
        GL.glDeleteRenderbuffers(2, [colour, depth])
        GL.glDeleteFramebuffers(1, [fbo])
