/* What dextar's compiled parts (dynamics/_kernel.c, laws/_reach.c) share: reading float64
 * buffers from Python. */
#ifndef DEXTAR_BUFFERS_H
#define DEXTAR_BUFFERS_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <string.h>

/* A C-contiguous float64 buffer of ``obj`` into ``view`` (writable when asked); -1 with a
 * Python error naming ``name`` otherwise. The caller releases it. */
static int get_buffer(PyObject *obj, Py_buffer *view, int writable, const char *name)
{
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) < 0)
        return -1;
    if (view->itemsize != 8 || view->format == NULL || strcmp(view->format, "d") != 0) {
        PyErr_Format(PyExc_TypeError, "%s must hold float64 values", name);
        PyBuffer_Release(view);
        return -1;
    }
    return 0;
}

/* The buffers of ``objs[0..n)`` into ``views``, those from index ``writable`` on writable:
 * 0, or -1 with a Python error and none held. */
static int get_buffers(PyObject *const *objs, Py_buffer *views, int n, int writable,
                       const char *const *names)
{
    for (int i = 0; i < n; i++) {
        if (get_buffer(objs[i], &views[i], i >= writable, names[i]) < 0) {
            while (i > 0)
                PyBuffer_Release(&views[--i]);
            return -1;
        }
    }
    return 0;
}

static void release_buffers(Py_buffer *views, int n)
{
    for (int i = 0; i < n; i++)
        PyBuffer_Release(&views[i]);
}

#endif
