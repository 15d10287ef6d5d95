/* The binary of an acausal FMU (FMI 2.0 Co-Simulation): every fmi2 function
 * forwards to an acausal.interop.fmu_instance.Instance in an embedded Python
 * interpreter (the importer's own when it is a Python process, such as
 * FMPy; else one started here from the Python the FMU was exported with).
 * The hybrid loop, the initialisation and the solver run there.
 *
 * Compiled by acausal.interop.fmu at export, with
 *   -DACS_MODEL_ID="<id>"    (the model identifier; the fmi2 names are exported
 *                              without prefix, as a shared library does)
 *   -DACS_PYTHON="..."       (sys.executable of the exporting Python)
 *   -DACS_LIBPYTHON="..."    (the libpython it is linked to)
 *   -DACS_SYSPATH="a:b:..."  (its sys.path, appended when acausal is not found)
 * FMI's types and calling conventions are written out below (FMI 2.0
 * standard, section 2.1); this file needs only Python.h.
 *
 * Every call: take the GIL, call the instance's method, hand the messages
 * it logged to the importer's logger, turn a Python exception into
 * fmi2Error with the exception's text logged (never a crash). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <dlfcn.h>
#include <stdlib.h>
#include <string.h>

typedef void *fmi2Component;
typedef void *fmi2ComponentEnvironment;
typedef void *fmi2FMUstate;
typedef unsigned int fmi2ValueReference;
typedef double fmi2Real;
typedef int fmi2Integer;
typedef int fmi2Boolean;
typedef char fmi2Char;
typedef const fmi2Char *fmi2String;
typedef char fmi2Byte;

typedef enum { fmi2OK, fmi2Warning, fmi2Discard, fmi2Error, fmi2Fatal, fmi2Pending } fmi2Status;
typedef enum { fmi2ModelExchange, fmi2CoSimulation } fmi2Type;
typedef enum { fmi2DoStepStatus, fmi2PendingStatus, fmi2LastSuccessfulTime,
               fmi2Terminated } fmi2StatusKind;

typedef void (*fmi2CallbackLogger)(fmi2ComponentEnvironment, fmi2String, fmi2Status,
                                   fmi2String, fmi2String, ...);
typedef void *(*fmi2CallbackAllocateMemory)(size_t, size_t);
typedef void (*fmi2CallbackFreeMemory)(void *);
typedef void (*fmi2StepFinished)(fmi2ComponentEnvironment, fmi2Status);

typedef struct {
    const fmi2CallbackLogger logger;
    const fmi2CallbackAllocateMemory allocateMemory;
    const fmi2CallbackFreeMemory freeMemory;
    const fmi2StepFinished stepFinished;
    const fmi2ComponentEnvironment componentEnvironment;
} fmi2CallbackFunctions;

#define fmi2True 1
#define fmi2False 0

#ifndef ACS_MODEL_ID
#define ACS_MODEL_ID ""
#endif
#ifndef ACS_PYTHON
#define ACS_PYTHON ""
#endif
#ifndef ACS_LIBPYTHON
#define ACS_LIBPYTHON ""
#endif
#ifndef ACS_SYSPATH
#define ACS_SYSPATH ""
#endif

#define EXPORT __attribute__((visibility("default")))

typedef struct {
    PyObject *obj;                        /* the Python Instance */
    fmi2CallbackLogger logger;
    fmi2ComponentEnvironment env;
    char *name;
} Inst;

/* The interpreter: the host's when it has one, else started once here as
 * the exporting Python would start (its executable as the program name:
 * a virtual environment's pyvenv.cfg and site-packages are found as when
 * that executable runs). */
static int ensure_python(void) {
    if (Py_IsInitialized())
        return 0;
    /* an importer that loaded this library with RTLD_LOCAL hid libpython's
     * symbols from the extension modules Python loads: make them global */
    if (ACS_LIBPYTHON[0] && !dlopen(ACS_LIBPYTHON, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD))
        dlopen(ACS_LIBPYTHON, RTLD_NOW | RTLD_GLOBAL);
    PyConfig config;
    PyConfig_InitPythonConfig(&config);
    config.install_signal_handlers = 0;   /* the importer's signals stay its own */
    if (ACS_PYTHON[0])
        PyConfig_SetBytesString(&config, &config.program_name, ACS_PYTHON);
    PyStatus status = Py_InitializeFromConfig(&config);
    PyConfig_Clear(&config);
    if (PyStatus_Exception(status) || !Py_IsInitialized())
        return -1;
    PyEval_SaveThread();   /* release the GIL: every call takes it */
    return 0;
}

static void log_text(fmi2CallbackLogger logger, fmi2ComponentEnvironment env,
                     const char *name, fmi2Status st, const char *cat, const char *text) {
    if (logger)
        logger(env, name ? name : "acausal", st, cat, "%s", text);
}

/* The text of the pending Python exception (cleared), into buf. */
static void exception_text(char *buf, size_t size) {
    PyObject *type, *value, *tb;
    PyErr_Fetch(&type, &value, &tb);
    PyErr_NormalizeException(&type, &value, &tb);
    PyObject *s = value ? PyObject_Str(value) : NULL;
    const char *tname = type ? ((PyTypeObject *)type)->tp_name : "error";
    const char *msg = s ? PyUnicode_AsUTF8(s) : NULL;
    snprintf(buf, size, "%s: %s", tname, msg ? msg : "(no message)");
    PyErr_Clear();
    Py_XDECREF(s);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(tb);
}

/* Hand the messages the instance logged to the importer. */
static void drain(Inst *c) {
    PyObject *msgs = PyObject_CallMethod(c->obj, "take_messages", NULL);
    if (!msgs) {
        PyErr_Clear();
        return;
    }
    Py_ssize_t n = PyList_Check(msgs) ? PyList_Size(msgs) : 0;
    for (Py_ssize_t i = 0; i < n; i++) {
        PyObject *m = PyList_GetItem(msgs, i);   /* (status, category, text) */
        long st = PyLong_AsLong(PyTuple_GetItem(m, 0));
        const char *cat = PyUnicode_AsUTF8(PyTuple_GetItem(m, 1));
        const char *text = PyUnicode_AsUTF8(PyTuple_GetItem(m, 2));
        if (PyErr_Occurred()) {
            PyErr_Clear();
            continue;
        }
        log_text(c->logger, c->env, c->name, (fmi2Status)st, cat, text);
    }
    Py_DECREF(msgs);
}

/* A Python exception of a call: logged, fmi2Error. */
static fmi2Status failed(Inst *c, const char *where) {
    char buf[4096], line[4200];
    exception_text(buf, sizeof buf);
    snprintf(line, sizeof line, "%s: %s", where, buf);
    drain(c);
    log_text(c->logger, c->env, c->name, fmi2Error, "logStatusError", line);
    return fmi2Error;
}

/* The status an instance method returned (an int), messages handed on. */
static fmi2Status finish(Inst *c, PyObject *r, const char *where) {
    if (!r)
        return failed(c, where);
    long st = PyLong_Check(r) ? PyLong_AsLong(r) : 0;
    Py_DECREF(r);
    drain(c);
    return (fmi2Status)st;
}

#define ENTER(c) if (!(c) || !((Inst *)(c))->obj) return fmi2Error; \
    Inst *I = (Inst *)(c); PyGILState_STATE gil = PyGILState_Ensure(); fmi2Status st
#define LEAVE PyGILState_Release(gil); return st

EXPORT const char *fmi2GetTypesPlatform(void) { return "default"; }
EXPORT const char *fmi2GetVersion(void) { return "2.0"; }

EXPORT fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType,
                                     fmi2String guid, fmi2String resourceLocation,
                                     const fmi2CallbackFunctions *functions,
                                     fmi2Boolean visible, fmi2Boolean loggingOn) {
    (void)visible;
    fmi2CallbackLogger logger = functions ? functions->logger : NULL;
    fmi2ComponentEnvironment env = functions ? functions->componentEnvironment : NULL;
    if (fmuType != fmi2CoSimulation) {
        log_text(logger, env, instanceName, fmi2Error, "logStatusError",
                 "this FMU supports Co-Simulation only");
        return NULL;
    }
    if (ensure_python() != 0) {
        log_text(logger, env, instanceName, fmi2Error, "logStatusError",
                 "could not start the Python interpreter that runs this FMU");
        return NULL;
    }
    /* the binary was compiled for one Python version (its C API): a host
     * running another one must not call into it */
    char want[16];
    snprintf(want, sizeof want, "%d.%d.", PY_MAJOR_VERSION, PY_MINOR_VERSION);
    if (strncmp(Py_GetVersion(), want, strlen(want)) != 0) {
        char line[256];
        snprintf(line, sizeof line, "this FMU was exported with Python %d.%d; the importer "
                 "runs Python %.10s", PY_MAJOR_VERSION, PY_MINOR_VERSION, Py_GetVersion());
        log_text(logger, env, instanceName, fmi2Error, "logStatusError", line);
        return NULL;
    }
    Inst *c = calloc(1, sizeof(Inst));
    if (!c)
        return NULL;
    c->logger = logger;
    c->env = env;
    c->name = strdup(instanceName ? instanceName : "acausal");
    PyGILState_STATE gil = PyGILState_Ensure();
    PyObject *mod = PyImport_ImportModule("acausal.interop.fmu_instance");
    if (!mod && ACS_SYSPATH[0]) {
        /* a Python without acausal (one started here): the exporter's paths,
         * as site directories (their .pth files make editable installs work) */
        PyErr_Clear();
        PyObject *site = PyImport_ImportModule("site");
        char *paths = strdup(ACS_SYSPATH), *save = NULL;
        for (char *p = strtok_r(paths, ":", &save); site && p;
             p = strtok_r(NULL, ":", &save)) {
            PyObject *r = PyObject_CallMethod(site, "addsitedir", "s", p);
            if (!r)
                PyErr_Clear();
            Py_XDECREF(r);
        }
        free(paths);
        Py_XDECREF(site);
        PyErr_Clear();
        mod = PyImport_ImportModule("acausal.interop.fmu_instance");
    }
    if (mod) {
        c->obj = PyObject_CallMethod(mod, "Instance", "ssssi", c->name, guid ? guid : "",
                                     resourceLocation ? resourceLocation : "",
                                     ACS_MODEL_ID, (int)loggingOn);
        Py_DECREF(mod);
    }
    if (!c->obj) {
        char buf[4096], line[4200];
        exception_text(buf, sizeof buf);
        snprintf(line, sizeof line, "fmi2Instantiate: %s", buf);
        log_text(logger, env, c->name, fmi2Error, "logStatusError", line);
        PyGILState_Release(gil);
        free(c->name);
        free(c);
        return NULL;
    }
    drain(c);
    PyGILState_Release(gil);
    return c;
}

EXPORT void fmi2FreeInstance(fmi2Component comp) {
    Inst *c = (Inst *)comp;
    if (!c)
        return;
    if (c->obj) {
        PyGILState_STATE gil = PyGILState_Ensure();
        PyObject *r = PyObject_CallMethod(c->obj, "free", NULL);
        if (!r)
            PyErr_Clear();
        Py_XDECREF(r);
        Py_CLEAR(c->obj);
        PyGILState_Release(gil);
    }
    free(c->name);
    free(c);
}

EXPORT fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n,
                                      const fmi2String categories[]) {
    ENTER(c);
    PyObject *cats = PyList_New(0);
    for (size_t i = 0; i < n; i++) {
        PyObject *s = PyUnicode_FromString(categories[i]);
        PyList_Append(cats, s);
        Py_DECREF(s);
    }
    st = finish(I, PyObject_CallMethod(I->obj, "set_debug_logging", "iO", (int)on, cats),
                "fmi2SetDebugLogging");
    Py_DECREF(cats);
    LEAVE;
}

EXPORT fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined,
                                      fmi2Real tolerance, fmi2Real startTime,
                                      fmi2Boolean stopTimeDefined, fmi2Real stopTime) {
    ENTER(c);
    st = finish(I, PyObject_CallMethod(I->obj, "setup_experiment", "idddi",
                                       (int)toleranceDefined, tolerance, startTime, stopTime,
                                       (int)stopTimeDefined), "fmi2SetupExperiment");
    LEAVE;
}

#define SIMPLE(fname, method) \
EXPORT fmi2Status fname(fmi2Component c) { \
    ENTER(c); st = finish(I, PyObject_CallMethod(I->obj, method, NULL), #fname); LEAVE; }

SIMPLE(fmi2EnterInitializationMode, "enter_initialization_mode")
SIMPLE(fmi2ExitInitializationMode, "exit_initialization_mode")
SIMPLE(fmi2Terminate, "terminate")
SIMPLE(fmi2Reset, "reset")
SIMPLE(fmi2CancelStep, "cancel_step")

static PyObject *vr_list(const fmi2ValueReference vr[], size_t n) {
    PyObject *l = PyList_New((Py_ssize_t)n);
    for (size_t i = 0; i < n; i++)
        PyList_SetItem(l, (Py_ssize_t)i, PyLong_FromUnsignedLong(vr[i]));
    return l;
}

EXPORT fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              fmi2Real value[]) {
    ENTER(c);
    PyObject *vrs = vr_list(vr, n);
    PyObject *r = PyObject_CallMethod(I->obj, "get_real", "O", vrs);
    Py_DECREF(vrs);
    if (!r) {
        st = failed(I, "fmi2GetReal");
    } else {
        st = fmi2OK;
        for (size_t i = 0; i < n; i++) {
            value[i] = PyFloat_AsDouble(PyList_GetItem(r, (Py_ssize_t)i));
            if (PyErr_Occurred()) {
                st = failed(I, "fmi2GetReal");
                break;
            }
        }
        Py_DECREF(r);
        if (st == fmi2OK)
            drain(I);
    }
    LEAVE;
}

EXPORT fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                              const fmi2Real value[]) {
    ENTER(c);
    PyObject *vrs = vr_list(vr, n), *vals = PyList_New((Py_ssize_t)n);
    for (size_t i = 0; i < n; i++)
        PyList_SetItem(vals, (Py_ssize_t)i, PyFloat_FromDouble(value[i]));
    st = finish(I, PyObject_CallMethod(I->obj, "set_real", "OO", vrs, vals), "fmi2SetReal");
    Py_DECREF(vrs);
    Py_DECREF(vals);
    LEAVE;
}

/* This FMU has Real variables only: the other types have no value references. */
static fmi2Status no_such(fmi2Component c, size_t n, const char *what) {
    if (n == 0)
        return fmi2OK;
    ENTER(c);
    st = finish(I, PyObject_CallMethod(I->obj, "no_variables", "s", what), what);
    LEAVE;
}

EXPORT fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 fmi2Integer value[]) {
    (void)vr; (void)value; return no_such(c, n, "fmi2GetInteger"); }
EXPORT fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 fmi2Boolean value[]) {
    (void)vr; (void)value; return no_such(c, n, "fmi2GetBoolean"); }
EXPORT fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                fmi2String value[]) {
    (void)vr; (void)value; return no_such(c, n, "fmi2GetString"); }
EXPORT fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 const fmi2Integer value[]) {
    (void)vr; (void)value; return no_such(c, n, "fmi2SetInteger"); }
EXPORT fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                 const fmi2Boolean value[]) {
    (void)vr; (void)value; return no_such(c, n, "fmi2SetBoolean"); }
EXPORT fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                const fmi2String value[]) {
    (void)vr; (void)value; return no_such(c, n, "fmi2SetString"); }

/* What the capability flags of modelDescription.xml say is not supported. */
static fmi2Status unsupported(fmi2Component c, const char *what) {
    ENTER(c);
    st = finish(I, PyObject_CallMethod(I->obj, "unsupported", "s", what), what);
    LEAVE;
}

EXPORT fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s; return unsupported(c, "fmi2GetFMUstate"); }
EXPORT fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) {
    (void)s; return unsupported(c, "fmi2SetFMUstate"); }
EXPORT fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) {
    (void)s; return unsupported(c, "fmi2FreeFMUstate"); }
EXPORT fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *size) {
    (void)s; (void)size; return unsupported(c, "fmi2SerializedFMUstateSize"); }
EXPORT fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[],
                                        size_t size) {
    (void)s; (void)b; (void)size; return unsupported(c, "fmi2SerializeFMUstate"); }
EXPORT fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t size,
                                          fmi2FMUstate *s) {
    (void)s; (void)b; (void)size; return unsupported(c, "fmi2DeSerializeFMUstate"); }
EXPORT fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[],
        size_t nu, const fmi2ValueReference z[], size_t nz, const fmi2Real dv[],
        fmi2Real dz[]) {
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return unsupported(c, "fmi2GetDirectionalDerivative"); }
EXPORT fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
        size_t n, const fmi2Integer order[], const fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return unsupported(c, "fmi2SetRealInputDerivatives"); }
EXPORT fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[],
        size_t n, const fmi2Integer order[], fmi2Real value[]) {
    (void)vr; (void)n; (void)order; (void)value;
    return unsupported(c, "fmi2GetRealOutputDerivatives"); }

EXPORT fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h,
                             fmi2Boolean noSetFMUStatePriorToCurrentPoint) {
    (void)noSetFMUStatePriorToCurrentPoint;
    ENTER(c);
    st = finish(I, PyObject_CallMethod(I->obj, "do_step", "dd", t, h), "fmi2DoStep");
    LEAVE;
}

EXPORT fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetStatus"); }
EXPORT fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s,
                                       fmi2Integer *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetIntegerStatus"); }
EXPORT fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s,
                                      fmi2String *value) {
    (void)s; (void)value; return unsupported(c, "fmi2GetStringStatus"); }

EXPORT fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value) {
    ENTER(c);
    PyObject *r = PyObject_CallMethod(I->obj, "real_status", "i", (int)s);
    if (!r) {
        st = failed(I, "fmi2GetRealStatus");
    } else {
        *value = PyFloat_AsDouble(r);
        Py_DECREF(r);
        st = PyErr_Occurred() ? failed(I, "fmi2GetRealStatus") : fmi2OK;
        if (st == fmi2OK)
            drain(I);
    }
    LEAVE;
}

EXPORT fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s,
                                       fmi2Boolean *value) {
    ENTER(c);
    PyObject *r = PyObject_CallMethod(I->obj, "boolean_status", "i", (int)s);
    if (!r) {
        st = failed(I, "fmi2GetBooleanStatus");
    } else {
        *value = PyObject_IsTrue(r) ? fmi2True : fmi2False;
        Py_DECREF(r);
        st = fmi2OK;
        drain(I);
    }
    LEAVE;
}
