"""Shared machinery of the workbench's features: proxy base, view provider, task panel, command.

Every feature module (``ght_curve``, ``composite_curve``, ...) holds its Proxy, ViewProvider and
Command, CurvesWB style, built on these bases. Proxies persist through ``__getstate__`` /
``__setstate__`` (FreeCAD 0.20) and ``dumps`` / ``loads`` (newer FreeCAD). View providers and task
panels are only created when ``FreeCAD.GuiUp``.

Failed recomputes. A feature whose input is refused (an unset link, a
:class:`ght_cad.core.errors.GHTError` such as a shape parameter outside [-1, 1], a negative tolerance, a
non-developable face; :data:`EXPECTED_ERRORS`) prints one line ``"<Label>: <message>"`` in the
Report view and goes to FreeCAD's error state (``State`` ``Invalid``, the tree's error mark,
``getStatusString()`` = the message, dependants skipped, the old shape kept), without a Python
traceback: :meth:`FeatureProxy.execute` raises :class:`RecomputeError` the way FreeCAD passes its
own C++ errors through Python (:func:`raise_reported`). Any other exception is a bug and keeps its
traceback. :func:`failed` is the one test for "the last recompute failed" (exports, task panels);
:func:`failed_input` finds a failed object a feature depends on.
"""

from __future__ import annotations

from typing import Any, Callable, Iterable, NoReturn, Sequence

import FreeCAD as App

from . import icon
from ght_cad.core.errors import GHTError

__all__ = [
    "SHAPE_PARAMETERS",
    "FeatureProxy",
    "ViewProviderBase",
    "ShapeParameterPanel",
    "MessagePanel",
    "MissingInput",
    "RecomputeError",
    "EXPECTED_ERRORS",
    "failed",
    "failed_input",
    "report_failure",
    "raise_reported",
    "require_links",
    "info_panel",
    "BaseCommand",
    "add_shape_parameters",
    "check_shape",
    "tolerance_property",
    "restore_constraints",
    "set_read_only",
    "new_feature",
    "register_command",
    "selected_links",
    "COMMANDS",
]

# (name, tooltip) of the spec's shape parameters: App::PropertyFloatConstraint in [-1, 1].
SHAPE_PARAMETERS = (
    ("Mu", "Shape parameter μ ∈ [-1, 1] (start side of the GHT seed)"),
    ("Nu", "Shape parameter ν ∈ [-1, 1] (end side of the GHT seed)"),
    ("Gamma", "Shape parameter γ ∈ [-1, 1]: -1 trigonometric (GBT, exact circles), 1 classical Bézier"),
)
_STEP = 0.05


def add_shape_parameters(obj: Any, group: str = "Shape", values: Sequence[float] = (0.0, 0.0, 0.0), prefix: str = "") -> None:
    """Add Mu, Nu, Gamma (optionally prefixed) as float-constraint properties in [-1, 1]."""
    for (name, tip), value in zip(SHAPE_PARAMETERS, values):
        pname = prefix + name
        if pname not in obj.PropertiesList:
            obj.addProperty("App::PropertyFloatConstraint", pname, group, tip)
        setattr(obj, pname, (float(value), -1.0, 1.0, _STEP))


def check_shape(mu: float, nu: float, gamma: float) -> None:
    """Raise :class:`ght_cad.core.errors.ShapeParameterError` if μ, ν or γ is outside [-1, 1] (no clamping)."""
    from ght_cad.core._validate import check_shape_parameter

    for n, v in (("mu", mu), ("nu", nu), ("gamma", gamma)):
        check_shape_parameter(n, v)


def tolerance_property(obj: Any, name: str = "Tolerance", *, zero_means: str | None = None) -> float | None:
    """The value of a tolerance property, refused unless finite and > 0.

    Args:
        obj: the feature.
        name: property name.
        zero_means: if given, 0 is allowed and documented as this (e.g. "automatic"); the
            function then returns None for 0.

    Raises:
        ght_cad.core.errors.GHTError: NaN, ±inf, a negative value, or 0 when ``zero_means`` is None.
    """
    import math

    from ght_cad.core.errors import GHTError

    v = float(getattr(obj, name))
    if zero_means is not None and v == 0.0:
        return None
    if not math.isfinite(v) or v <= 0.0:
        allowed = f"a finite number >= 0 (0: {zero_means})" if zero_means is not None else "a finite number > 0"
        raise GHTError(f"{obj.Label}.{name}={v!r} is not allowed; it must be {allowed}")
    return v


def restore_constraints(obj: Any) -> None:
    """Re-apply the [-1, 1] range to every Mu/Nu/Gamma-like property (lost on file reload in 0.20)."""
    for pname in obj.PropertiesList:
        if any(pname.endswith(n) for n, _ in SHAPE_PARAMETERS) and obj.getTypeIdOfProperty(pname) == "App::PropertyFloatConstraint":
            setattr(obj, pname, (float(getattr(obj, pname)), -1.0, 1.0, _STEP))


def float_list(values: Any) -> list[float]:
    """Flat list of floats for a ``App::PropertyFloatList`` (e.g. n planes -> 4n coordinates)."""
    import numpy as np

    return [float(x) for x in np.asarray(values, dtype=float).ravel()]


def link_sub_list(links: Iterable[tuple[Any, Any]]) -> list[tuple[Any, Any]]:
    """``[(object, sub-element names)]`` for a ``LinkSubList``; an empty sub-list becomes ``""``
    ("the whole object": FreeCAD drops a link whose sub-list is empty)."""
    return [(o, list(subs) if subs else "") for o, subs in links]


def set_read_only(obj: Any, names: Iterable[str]) -> None:
    """Editor mode 1 (read-only in the property editor) for output properties."""
    for n in names:
        obj.setEditorMode(n, 1)


class FeatureProxy:
    """Base proxy: type tag, persistence hooks and error reporting around ``compute``."""

    Type = "GHT::Feature"

    def __init__(self, obj: Any) -> None:
        obj.Proxy = self
        self.Type = type(self).Type
        self.setup(obj)

    # -- to override ------------------------------------------------------------------
    def setup(self, obj: Any) -> None:
        """Add properties (called once at creation)."""

    def compute(self, obj: Any) -> None:
        """Build ``obj.Shape`` (and output properties) from the input properties."""

    # -- FreeCAD hooks --------------------------------------------------------------------
    def execute(self, obj: Any) -> None:
        """FreeCAD's recompute hook: :meth:`compute`, with refused input reported without traceback.

        An expected error (:data:`EXPECTED_ERRORS`) or a failed input (:func:`failed_input`) prints
        one line and puts the feature in FreeCAD's error state (:func:`report_failure`); any other
        exception propagates with its traceback, after a line naming the feature.
        """
        message = self.recompute_message(obj)
        if message is not None:  # outside any try block: see raise_reported
            report_failure(obj, message)

    def recompute_message(self, obj: Any) -> str | None:
        """Run :meth:`compute`; the message of a refused input, or None when the shape was built.

        Raises:
            Exception: anything but :data:`EXPECTED_ERRORS` from :meth:`compute` (a bug).
        """
        bad = failed_input(obj)
        if bad is not None:  # e.g. obj.recompute() alone: never build on a stale input shape
            return f"its input {bad.Label} failed to recompute ({bad.getStatusString()}); fix that first"
        placement = obj.Placement if hasattr(obj, "Placement") else None
        try:
            self.compute(obj)
        except EXPECTED_ERRORS as exc:
            return str(exc) or type(exc).__name__
        except Exception as exc:  # a bug: FreeCAD prints the traceback; say which feature first
            App.Console.PrintError(f"{obj.Label}: {type(exc).__name__}: {exc}\n")
            raise
        if placement is not None:  # a new Shape carries an identity placement: keep the user's
            obj.Placement = placement
        return None

    def onDocumentRestored(self, obj: Any) -> None:
        restore_constraints(obj)
        self.restored(obj)

    def restored(self, obj: Any) -> None:
        """Re-apply editor modes etc. after a file is opened."""

    def __getstate__(self) -> dict:
        return {"Type": type(self).Type}

    def __setstate__(self, state: Any) -> None:
        if isinstance(state, dict):
            self.Type = state.get("Type", type(self).Type)
        return None

    def dumps(self) -> dict:
        return self.__getstate__()

    def loads(self, state: Any) -> None:
        return self.__setstate__(state)


class MissingInput(Exception):
    """A task panel cannot edit its feature: a link it needs is unset (the message says which)."""


#: Exceptions a feature's :meth:`FeatureProxy.compute` raises for input it refuses (an expected
#: error, reported as one line without traceback); anything else is a bug.
EXPECTED_ERRORS: tuple[type[BaseException], ...] = (GHTError, MissingInput)

#: False: :func:`raise_reported` raises plainly (FreeCAD then prints a traceback); for tests.
QUIET_ERRORS = True


class RecomputeError(GHTError):
    """Raised by :meth:`FeatureProxy.execute` for refused input; FreeCAD's status string is its message.

    Its one argument is FreeCAD's exception dictionary ``{"swhat": message, "breported": True}``
    (see :func:`raise_reported`); ``str()`` gives the message either way.
    """

    def __str__(self) -> str:
        arg = self.args[0] if len(self.args) == 1 else None
        if isinstance(arg, dict):
            return str(arg.get("swhat", ""))
        return super().__str__()


def _c_api() -> tuple[Any, Any] | None:
    """``(PyErr_Restore, Py_IncRef)`` of the running interpreter through ctypes, or None."""
    try:
        import ctypes

        restore = ctypes.PYFUNCTYPE(None, ctypes.py_object, ctypes.py_object, ctypes.c_void_p)(("PyErr_Restore", ctypes.pythonapi))
        incref = ctypes.PYFUNCTYPE(None, ctypes.py_object)(("Py_IncRef", ctypes.pythonapi))
    except Exception:  # noqa: BLE001 - no ctypes / not CPython: plain raise
        return None
    return restore, incref


_C_API = _c_api()


def raise_reported(message: str) -> NoReturn:
    """Raise :class:`RecomputeError` so that FreeCAD marks the feature failed without a traceback.

    FreeCAD 0.20 has no Python call that puts a ``FeaturePython`` in the error state: ``State`` is
    read-only, and ``execute`` returning False or raising ``NotImplementedError`` counts as success.
    Any other exception out of ``execute`` marks the object ``Invalid`` with the exception text as
    its status string, and ``Base::PyException::ReportException`` prints the Python traceback
    unless the exception is flagged as already reported. The flag is read from FreeCAD's exception
    dictionary (the form in which FreeCAD passes its C++ exceptions through Python): an exception
    whose value is a ``dict`` with ``"swhat"`` (the message) and ``"breported": True``. Python code
    cannot raise a bare dict as the exception value, so the error indicator is set with the C API
    ``PyErr_Restore`` (``ctypes.pythonapi``). Call this only outside ``try`` / ``with`` blocks in
    ``execute``: a handler on the way normalizes the value into an exception object.

    Where that does not hold (a tracer such as a debugger normalizes every exception; Python >= 3.12
    always does; no ctypes; :data:`QUIET_ERRORS` False) FreeCAD prints the traceback as for any
    exception, and the state and status string are the same.

    Args:
        message: the status string, e.g. ``"Flat: no Source linked"``.

    Raises:
        RecomputeError: always.
    """
    value = {"swhat": str(message), "breported": True}
    if QUIET_ERRORS and _C_API is not None:
        restore, incref = _C_API
        incref(RecomputeError)  # PyErr_Restore steals both references
        incref(value)
        restore(RecomputeError, value, None)  # the error indicator is set: the ctypes call raises it
    raise RecomputeError(value)


def report_failure(obj: Any, message: str) -> NoReturn:
    """One error line ``"<Label>: <message>"`` in the Report view, then :func:`raise_reported`.

    The label is not repeated when the message already starts with it (``"Flat: no Source
    linked"``). FreeCAD then adds its own "Recompute failed! Please check report view." line.

    Raises:
        RecomputeError: always (FreeCAD marks ``obj`` Invalid with ``message`` as status string).
    """
    label = str(obj.Label)
    line = message if message.startswith((label + ":", label + ".")) else f"{label}: {message}"
    App.Console.PrintError(line.replace("\n", " ") + "\n")
    raise_reported(message)


def failed(obj: Any) -> bool:
    """True when the last recompute of ``obj`` failed (FreeCAD state ``Invalid`` or ``Error``).

    FreeCAD keeps the old shape of such an object and skips what depends on it; the shape must not
    be exported or built on. ``obj.getStatusString()`` is the reason.
    """
    state = getattr(obj, "State", None) or ()
    return "Invalid" in state or "Error" in state


def failed_input(obj: Any) -> Any | None:
    """The first object ``obj`` depends on (``OutListRecursive``) whose last recompute failed, or None."""
    for dep in getattr(obj, "OutListRecursive", None) or ():
        if failed(dep):
            return dep
    return None


def _link_empty(value: Any) -> bool:
    """True for an unset link value: None, [], a LinkSub ``(None, ...)`` or a list of such."""
    if value is None:
        return True
    if isinstance(value, (list, tuple)):
        if not value:
            return True
        if isinstance(value, tuple) and len(value) == 2 and not isinstance(value[0], tuple):
            return value[0] is None  # LinkSub (object, sub-names)
        return all(_link_empty(v) if isinstance(v, tuple) else v is None for v in value)
    return False


def require_links(obj: Any, *names: str) -> None:
    """Raise :class:`MissingInput` naming the first of the link properties ``names`` that is unset.

    The message says where to set it: ``"<Label>: Curve is not linked; set it in the property
    editor (Input → Curve: <the property's tooltip>), then double-click again"``.
    """
    for n in names:
        if _link_empty(getattr(obj, n, None)):
            group = obj.getGroupOfProperty(n) if n in obj.PropertiesList else "Data"
            tip = obj.getDocumentationOfProperty(n) if n in obj.PropertiesList else ""
            raise MissingInput(f"{obj.Label}: {n} is not linked; set it in the property editor ({group} → {n}"
                               + (f": {tip}" if tip else "") + "), then double-click again")


def info_panel(obj: Any, links: Sequence[str], hint: str) -> "MessagePanel":
    """Panel of a feature without shape parameters of its own: its state and what to edit where.

    Raises:
        MissingInput: one of ``links`` is unset (see :func:`require_links`).
    """
    require_links(obj, *links)
    state = f"last recompute failed: {obj.getStatusString()}" if failed(obj) else "up to date" if "Touched" not in obj.State else "not yet recomputed"
    return MessagePanel(obj, f"{obj.Label}: {state}.\n{hint}")


class ViewProviderBase:
    """View provider: icon, double-click opens the feature's task panel.

    ``panel_factory(obj)`` builds the panel; one that raises :class:`MissingInput` (an unset link)
    gets a :class:`MessagePanel` with that message instead, never a traceback.
    """

    icon_name = "GHT_Workbench"
    panel_factory: Callable[[Any], Any] | None = None
    #: the panel the most recent setEdit opened (for macros and the GUI check)
    last_panel: Any = None
    #: default colours (r, g, b in 0..1) and line width of new objects
    shape_color: tuple | None = None
    line_color: tuple | None = None
    line_width: float | None = None

    def __init__(self, vobj: Any) -> None:
        vobj.Proxy = self
        for prop, value in (("ShapeColor", self.shape_color), ("LineColor", self.line_color), ("LineWidth", self.line_width)):
            if value is not None and hasattr(vobj, prop):
                setattr(vobj, prop, value)

    def attach(self, vobj: Any) -> None:
        self.Object = vobj.Object

    @property
    def obj(self) -> Any:
        """The feature (None before ``attach``)."""
        return getattr(self, "Object", None)

    def getIcon(self) -> str:
        return icon(self.icon_name)

    def claimChildren(self) -> list:
        return []

    def setEdit(self, vobj: Any, mode: int = 0) -> bool:
        if mode != 0 or type(self).panel_factory is None:
            return False
        import FreeCADGui as Gui

        try:
            panel = type(self).panel_factory(vobj.Object)
        except MissingInput as exc:
            panel = MessagePanel(vobj.Object, str(exc))
        ViewProviderBase.last_panel = panel
        Gui.Control.showDialog(panel)
        return True

    def unsetEdit(self, vobj: Any, mode: int = 0) -> bool:
        import FreeCADGui as Gui

        Gui.Control.closeDialog()
        return True

    def doubleClicked(self, vobj: Any) -> bool:
        import FreeCADGui as Gui

        Gui.ActiveDocument.setEdit(vobj.Object.Name, 0)
        return True

    def __getstate__(self) -> None:
        return None

    def __setstate__(self, state: Any) -> None:
        return None

    def dumps(self) -> None:
        return None

    def loads(self, state: Any) -> None:
        return None


def _qt() -> tuple[Any, Any]:
    try:
        from PySide2 import QtCore, QtWidgets
    except ImportError:  # pragma: no cover - other FreeCAD builds
        from PySide import QtCore  # type: ignore
        from PySide import QtGui as QtWidgets  # type: ignore
    return QtCore, QtWidgets


class ShapeParameterPanel:
    """Task panel with one slider + spin box per float property; every change recomputes (live preview).

    OK keeps the values, Cancel restores the values the feature had when the panel opened.
    """

    #: the most recently opened panel (for macros and the GUI test)
    last: "ShapeParameterPanel | None" = None

    def __init__(self, obj: Any, names: Sequence[str] | None = None, title: str = "Shape parameters") -> None:
        QtCore, QtWidgets = _qt()
        if obj is None:
            raise MissingInput(f"{title}: no feature to edit; link one in the property editor")
        names = list(names) if names is not None else [n for n, _ in SHAPE_PARAMETERS if n in obj.PropertiesList]
        if not names:
            raise MissingInput(f"{obj.Label} has no shape parameters (Mu, Nu, Gamma) to edit; link a GHT feature")
        ShapeParameterPanel.last = self
        self.obj = obj
        self.names = names
        self.saved = {n: float(getattr(obj, n)) for n in self.names}
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(f"{obj.Label}: {title}")
        layout = QtWidgets.QFormLayout(self.form)
        self.spins: dict[str, Any] = {}
        self.sliders: dict[str, Any] = {}
        for n in self.names:
            row = QtWidgets.QHBoxLayout()
            spin = QtWidgets.QDoubleSpinBox()
            spin.setRange(-1.0, 1.0)
            spin.setDecimals(3)
            spin.setSingleStep(_STEP)
            spin.setValue(self.saved[n])
            spin.setToolTip(obj.getDocumentationOfProperty(n))
            slider = QtWidgets.QSlider(QtCore.Qt.Horizontal)
            slider.setRange(-1000, 1000)
            slider.setValue(int(round(self.saved[n] * 1000)))
            spin.valueChanged.connect(lambda v, n=n: self._changed(n, v, "spin"))
            slider.valueChanged.connect(lambda v, n=n: self._changed(n, v / 1000.0, "slider"))
            row.addWidget(slider)
            row.addWidget(spin)
            layout.addRow(n, row)
            self.spins[n] = spin
            self.sliders[n] = slider
        self.status = QtWidgets.QLabel("")
        self.status.setWordWrap(True)
        layout.addRow(self.status)
        self.status.setText(self.errors())  # a feature that fails already (e.g. an unset link) says why

    @property
    def message(self) -> str:
        """The status line (recompute errors of the feature and its dependants; "" if none)."""
        return self.status.text()

    def _changed(self, name: str, value: float, source: str) -> None:
        if source == "slider":
            self.spins[name].blockSignals(True)
            self.spins[name].setValue(value)
            self.spins[name].blockSignals(False)
        else:
            self.sliders[name].blockSignals(True)
            self.sliders[name].setValue(int(round(value * 1000)))
            self.sliders[name].blockSignals(False)
        self.preview(name, value)

    def preview(self, name: str, value: float) -> None:
        """Write the value and recompute the feature (and what depends on it)."""
        setattr(self.obj, name, float(value))
        try:
            self.obj.Document.recompute()
            self.status.setText(self.errors())
        except Exception as exc:  # keep the panel open on a bad combination
            self.status.setText(str(exc))

    def errors(self) -> str:
        """Status messages of the feature and its dependants whose recompute failed ("" if none).

        A failing ``execute`` does not make ``Document.recompute()`` raise: FreeCAD marks the
        object Invalid and keeps its old shape, so the panel has to look at the states (:func:`failed`).
        """
        objs = [self.obj] + list(getattr(self.obj, "InListRecursive", []))
        bad = [o for o in objs if failed(o)]
        return "\n".join(f"{o.Label}: {o.getStatusString()}" for o in bad)

    def accept(self) -> bool:
        import FreeCADGui as Gui

        self.obj.Document.recompute()
        Gui.Control.closeDialog()
        if Gui.ActiveDocument is not None:
            Gui.ActiveDocument.resetEdit()
        return True

    def reject(self) -> bool:
        import FreeCADGui as Gui

        for n, v in self.saved.items():
            setattr(self.obj, n, v)
        self.obj.Document.recompute()
        Gui.Control.closeDialog()
        if Gui.ActiveDocument is not None:
            Gui.ActiveDocument.resetEdit()
        return True

    def getStandardButtons(self) -> int:
        _, QtWidgets = _qt()
        return int(QtWidgets.QDialogButtonBox.Ok | QtWidgets.QDialogButtonBox.Cancel)


class MessagePanel:
    """Task panel that only shows a message (a feature with an unset link, or without parameters).

    Attributes:
        message: the text shown.
    """

    def __init__(self, obj: Any, message: str, title: str | None = None) -> None:
        QtCore, QtWidgets = _qt()
        self.obj = obj
        self.message = message
        self.form = QtWidgets.QWidget()
        self.form.setWindowTitle(title or f"{obj.Label}")
        layout = QtWidgets.QVBoxLayout(self.form)
        self.label = QtWidgets.QLabel(message)
        self.label.setWordWrap(True)
        self.label.setTextInteractionFlags(QtCore.Qt.TextSelectableByMouse)
        layout.addWidget(self.label)

    def _close(self) -> bool:
        import FreeCADGui as Gui

        Gui.Control.closeDialog()
        if Gui.ActiveDocument is not None:
            Gui.ActiveDocument.resetEdit()
        return True

    def accept(self) -> bool:
        return self._close()

    def reject(self) -> bool:
        return self._close()

    def getStandardButtons(self) -> int:
        _, QtWidgets = _qt()
        return int(QtWidgets.QDialogButtonBox.Close)


def new_feature(
    doc: Any, name: str, proxy_cls: type, vp_cls: type | None, type_id: str = "Part::FeaturePython"
) -> Any:
    """Create a feature with its proxy and (GUI only) view provider."""
    if doc is None:
        doc = App.ActiveDocument or App.newDocument()
    obj = doc.addObject(type_id, name)
    proxy_cls(obj)
    if App.GuiUp and vp_cls is not None:
        vp_cls(obj.ViewObject)
    return obj


# name -> command instance; filled by each feature module's ``register`` and used by init_gui.
COMMANDS: dict[str, Any] = {}


class BaseCommand:
    """Command base: resources from class attributes, active with an open document."""

    name = "GHT_Base"
    icon_name = "GHT_Workbench"
    menu_text = ""
    tooltip = ""

    def GetResources(self) -> dict:
        return {"Pixmap": icon(self.icon_name), "MenuText": self.menu_text, "ToolTip": self.tooltip}

    def IsActive(self) -> bool:
        return App.ActiveDocument is not None

    def Activated(self) -> None:  # pragma: no cover - overridden
        raise NotImplementedError

    def open_panel(self, obj: Any) -> None:
        """Open the feature's task panel (live preview of its shape parameters) in the GUI."""
        if App.GuiUp:
            import FreeCADGui as Gui

            Gui.ActiveDocument.setEdit(obj.Name, 0)


def selected_links(kind: str) -> list[tuple[Any, str]]:
    """The GUI selection as links ``(object, "<kind>N")``: every selected sub-element named
    ``kind...`` (``"Edge"``, ``"Face"``), and for a whole object selected without sub-elements its
    only such element, when its shape has exactly one."""
    import FreeCADGui as Gui

    links = []
    for sel in Gui.Selection.getSelectionEx():
        subs = [s for s in sel.SubElementNames if s.startswith(kind)]
        if subs:
            links += [(sel.Object, s) for s in subs]
        elif hasattr(sel.Object, "Shape") and len(getattr(sel.Object.Shape, kind + "s")) == 1:
            links.append((sel.Object, kind + "1"))
    return links


def register_command(cmd: BaseCommand) -> None:
    """Register with FreeCADGui (GUI only) and remember it for the workbench toolbar/menu."""
    COMMANDS[cmd.name] = cmd
    if App.GuiUp:
        import FreeCADGui as Gui

        Gui.addCommand(cmd.name, cmd)
