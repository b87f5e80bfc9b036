// The Python module `atonlab` (docs/python.md): its docstring, version and
// exceptions. An input error raises atonlab.InputError (a ValueError) with the
// command line's sentence and `file`, `line`, `key`, `option` attributes; no
// GL context raises atonlab.NoContextError; a study file the store refuses
// raises atonlab.StudyFileError (an OSError) with `file`.
#include <pybind11/pybind11.h>

#include <filesystem>
#include <system_error>

#include "atonlab/common/input_error.h"
#include "atonlab/stimuli/gl/context.h"
#include "atonlab/store/error.h"
#include "bindings.h"

namespace atonlab::python {

namespace {

PyObject* g_input_error = nullptr;
PyObject* g_input_file_not_found = nullptr;  // an InputError and a FileNotFoundError
PyObject* g_no_context = nullptr;
PyObject* g_study_file_error = nullptr;

PyObject* new_exception(py::module_& m, const char* name, const char* doc, PyObject* base) {
    const std::string qualified = std::string("atonlab.") + name;
    PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
    if (!type) throw py::error_already_set();
    m.add_object(name, py::handle(type));  // the module keeps a reference; so does this file (never released)
    Py_INCREF(type);
    return type;
}

py::object optional_text(const std::string& s) {
    return s.empty() ? py::object(py::none()) : py::object(py::str(s));
}

/// Raises InputError(what()) with the location's parts as attributes (None where unknown).
void raise_input_error(const InputError& e) {
    const SourceLocation where = e.where().value_or(SourceLocation{});
    // An error about a whole file (no line) that is not there: a missing file,
    // also a FileNotFoundError (InputFileNotFoundError).
    std::error_code ec;
    const bool missing =
        !where.file.empty() && where.line == 0 && !std::filesystem::exists(std::filesystem::path(where.file), ec);
    PyObject* type = missing ? g_input_file_not_found : g_input_error;
    py::object instance = py::reinterpret_steal<py::object>(PyObject_CallFunction(type, "s", e.what()));
    if (!instance) throw py::error_already_set();
    if (missing) instance.attr("filename") = py::str(where.file);
    instance.attr("file") = optional_text(where.file);
    instance.attr("line") = where.line > 0 ? py::object(py::int_(where.line)) : py::object(py::none());
    instance.attr("key") = optional_text(where.key);
    instance.attr("option") = optional_text(where.option);
    instance.attr("message") = py::str(e.message());
    PyErr_SetObject(type, instance.ptr());
}

void raise_study_file_error(const store::StoreError& e) {
    py::object instance =
        py::reinterpret_steal<py::object>(PyObject_CallFunction(g_study_file_error, "s", e.what()));
    if (!instance) throw py::error_already_set();
    instance.attr("file") = py::str(e.file().string());
    PyErr_SetObject(g_study_file_error, instance.ptr());
}

}  // namespace

void bind_exceptions(py::module_& m) {
    g_input_error = new_exception(
        m, "InputError",
        "Bad input (a scene or protocol file, an override, an argument): str(e) is the sentence the command line "
        "prints; e.file, e.line (1-based) and e.key say where, e.option names the argument or command-line option "
        "that gave the value (None where unknown).",
        PyExc_ValueError);
    py::tuple file_bases = py::make_tuple(py::handle(g_input_error), py::handle(PyExc_FileNotFoundError));
    g_input_file_not_found = new_exception(
        m, "InputFileNotFoundError",
        "An input file that does not exist (a scene, protocol, script or image file): an InputError and a "
        "FileNotFoundError (e.filename names it).",
        file_bases.ptr());
    g_no_context = new_exception(
        m, "NoContextError",
        "No OpenGL 4.5 context can be made on this machine (rendering, psf, check and run need one); str(e) says why.",
        PyExc_RuntimeError);
    g_study_file_error = new_exception(
        m, "StudyFileError",
        "A study file the store refuses or cannot write (not a study, damaged, a newer schema, disk full); what is "
        "stored stays as it was. e.file names it.",
        PyExc_OSError);
    for (const char* attribute : {"file", "line", "key", "option", "message"})
        PyObject_SetAttrString(g_input_error, attribute, Py_None);
    PyObject_SetAttrString(g_study_file_error, "file", Py_None);

    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            raise_input_error(e);
        } catch (const gl::ContextUnavailable& e) {
            PyErr_SetString(g_no_context, e.what());
        } catch (const store::StoreError& e) {
            raise_study_file_error(e);
        }
    });
}

}  // namespace atonlab::python

PYBIND11_MODULE(_atonlab, m) {
    m.doc() =
        "atonlab from Python (docs/python.md): scenes rendered to numpy arrays (cd/m², linear Rec.709), the tone "
        "mappers, glare models and Allard's law on any array, protocols checked and run, studies read as pandas "
        "DataFrames and analysed, psychometric functions fitted. Luminance in cd/m², intensity in cd, angles in "
        "degrees, time in seconds.";
    m.attr("__version__") = ATONLAB_VERSION;
    atonlab::python::bind_exceptions(m);
    atonlab::python::bind_images(m);
    atonlab::python::bind_render(m);
    atonlab::python::bind_study(m);
}
