/* The reference LWPR library (Klanke & Vijayakumar) called from Python one sample at a time, as cerebx's
   `LWPR.update` is called: a minimal CPython module for run.sh's comparison, in the shape of the library's own
   Python 2 binding (python/lwprmodule.c: the pair parsed as two ndarrays, copied into the model's buffers,
   `lwpr_update`, the prediction returned as a new array). Not part of cerebx.

   lwpr_c.Model(n_in, init_D, init_alpha, w_gen, penalty)  (w_gen, penalty < 0: the library's defaults)
   .update(x, y) -> ndarray (1,)    .predict(x) -> ndarray (1,)    .receptive_fields -> int */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>
#include <lwpr.h>

typedef struct {
  PyObject_HEAD
  LWPR_Model model;
  double x[64], y[1], yp[1];
  int ready;
} Model;

/* copy n doubles of a 1-D ndarray into dst (converted when it is not a contiguous float64 array) */
static int take(PyArrayObject *a, int n, double *dst) {
  PyArrayObject *c = (PyArrayObject *)PyArray_FROMANY((PyObject *)a, NPY_DOUBLE, 1, 1, NPY_ARRAY_IN_ARRAY);
  if (c == NULL) return -1;
  if (PyArray_DIM(c, 0) != n) {
    PyErr_Format(PyExc_ValueError, "expected %d values, got %ld", n, (long)PyArray_DIM(c, 0));
    Py_DECREF(c);
    return -1;
  }
  memcpy(dst, PyArray_DATA(c), sizeof(double) * n);
  Py_DECREF(c);
  return 0;
}

static PyObject *out(const double *v) {
  npy_intp dim = 1;
  PyObject *a = PyArray_SimpleNew(1, &dim, NPY_DOUBLE);
  if (a != NULL) memcpy(PyArray_DATA((PyArrayObject *)a), v, sizeof(double));
  return a;
}

static int model_init(Model *self, PyObject *args, PyObject *kw) {
  int n_in;
  double init_D, init_alpha, w_gen = -1.0, penalty = -1.0;
  if (!PyArg_ParseTuple(args, "idd|dd", &n_in, &init_D, &init_alpha, &w_gen, &penalty)) return -1;
  if (n_in < 1 || n_in > 64) {
    PyErr_SetString(PyExc_ValueError, "n_in must be 1..64");
    return -1;
  }
  if (!lwpr_init_model(&self->model, n_in, 1, "reference")) {
    PyErr_SetString(PyExc_MemoryError, "lwpr_init_model failed");
    return -1;
  }
  self->ready = 1;
  lwpr_set_init_D_spherical(&self->model, init_D);
  lwpr_set_init_alpha(&self->model, init_alpha);
  if (w_gen >= 0) self->model.w_gen = w_gen;
  if (penalty >= 0) self->model.penalty = penalty;
  return 0;
}

static void model_dealloc(Model *self) {
  if (self->ready) lwpr_free_model(&self->model);
  Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *model_update(Model *self, PyObject *args) {
  PyArrayObject *x, *y;
  if (!PyArg_ParseTuple(args, "O!O!", &PyArray_Type, &x, &PyArray_Type, &y)) return NULL;
  if (take(x, self->model.nIn, self->x) || take(y, 1, self->y)) return NULL;
  lwpr_update(&self->model, self->x, self->y, self->yp, NULL);
  return out(self->yp);
}

static PyObject *model_predict(Model *self, PyObject *args) {
  PyArrayObject *x;
  if (!PyArg_ParseTuple(args, "O!", &PyArray_Type, &x)) return NULL;
  if (take(x, self->model.nIn, self->x)) return NULL;
  lwpr_predict(&self->model, self->x, 0.001, self->yp, NULL, NULL);
  return out(self->yp);
}

static PyObject *model_rfs(Model *self, void *closure) { return PyLong_FromLong(self->model.sub[0].numRFS); }

static PyMethodDef model_methods[] = {
    {"update", (PyCFunction)model_update, METH_VARARGS, "Train on one pair; returns the prediction."},
    {"predict", (PyCFunction)model_predict, METH_VARARGS, "Prediction at x (cutoff 0.001)."},
    {NULL, NULL, 0, NULL}};

static PyGetSetDef model_getset[] = {{"receptive_fields", (getter)model_rfs, NULL, NULL, NULL}, {NULL}};

static PyTypeObject ModelType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "lwpr_c.Model",
    .tp_basicsize = sizeof(Model),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)model_init,
    .tp_dealloc = (destructor)model_dealloc,
    .tp_methods = model_methods,
    .tp_getset = model_getset,
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "lwpr_c", NULL, -1, NULL};

PyMODINIT_FUNC PyInit_lwpr_c(void) {
  import_array();
  if (PyType_Ready(&ModelType) < 0) return NULL;
  PyObject *m = PyModule_Create(&module);
  if (m == NULL) return NULL;
  Py_INCREF(&ModelType);
  PyModule_AddObject(m, "Model", (PyObject *)&ModelType);
  return m;
}
