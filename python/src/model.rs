//! `flexmech.Model`: a model's tables, read from a file or text or written
//! with builder calls that mirror the Rust `ModelBuilder`, changed with the
//! study key paths (`model.set("joint.screw.pitch", 0.05)`), and checked by
//! the model-file validation before anything runs.

use std::path::PathBuf;
use std::sync::OnceLock;

use flexmech::model::{parse_model_with, JointRegistry, Model};
use flexmech::studies::key_path::{lookup_mut, KeyPath, Segment};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use toml::{Table, Value};

use crate::convert::{dict_to_table, to_python, to_toml};
use crate::errors::{from_model_error, key_error};

/// flexmech's joint kinds (the registry every model is read with).
pub fn registry() -> &'static JointRegistry {
    static REGISTRY: OnceLock<JointRegistry> = OnceLock::new();
    REGISTRY.get_or_init(JointRegistry::builtin)
}

/// A model: its model-file tables, where they came from, and the checked
/// Rust model once it has been read.
#[pyclass(name = "Model", module = "flexmech")]
#[derive(Clone)]
pub struct PyModel {
    table: Table,
    /// The text the model was read from, while it is unchanged: what runs
    /// and what its result file stores, comments and all.
    text: Option<String>,
    /// The model file or text name; None for a model built in Python.
    file: Option<PathBuf>,
    /// Whether the text is still the user's (error lines refer to it).
    lines: bool,
    /// The checked model, while the tables are unchanged since.
    checked: Option<Model>,
}

impl PyModel {
    /// The model of `text` read from `file`, checked.
    fn read(py: Python<'_>, text: String, file: PathBuf) -> PyResult<Self> {
        let model = parse_model_with(&text, &file, registry())
            .map_err(|e| from_model_error(py, &e, Some(&file), true))?;
        // A text that the validation read is TOML.
        let table: Table = toml::from_str(&text).unwrap_or_default();
        Ok(Self {
            table,
            text: Some(text),
            file: Some(file),
            lines: true,
            checked: Some(model),
        })
    }

    /// The model's text: as read while unchanged, else the tables written.
    pub fn text(&self) -> String {
        match &self.text {
            Some(t) => t.clone(),
            None => toml::to_string(&self.table).unwrap_or_default(),
        }
    }

    /// The path the model is read under, for messages and result files.
    fn message_path(&self) -> PathBuf {
        match &self.file {
            Some(f) => f.clone(),
            None => PathBuf::from(format!("{} (built in Python)", self.name())),
        }
    }

    /// The checked Rust model (read and cached on first use).
    pub fn checked(&mut self, py: Python<'_>) -> PyResult<Model> {
        if let Some(m) = &self.checked {
            return Ok(m.clone());
        }
        let model = self.validate(py, None)?;
        self.checked = Some(model.clone());
        Ok(model)
    }

    /// Reads the model's tables (`None`: its own, as its text while
    /// unchanged; else `table` written as TOML) through the model-file
    /// validation.
    fn validate(&self, py: Python<'_>, table: Option<&Table>) -> PyResult<Model> {
        let (text, lines) = match table {
            None => (self.text(), self.lines && self.text.is_some()),
            Some(t) => (toml::to_string(t).unwrap_or_default(), false),
        };
        let path = self.message_path();
        parse_model_with(&text, &path, registry())
            .map_err(|e| from_model_error(py, &e, self.file.as_deref(), lines))
    }

    /// The `ModelError` exception of an error about this model (met when
    /// it is built for a run).
    pub fn model_error(&self, py: Python<'_>, e: &flexmech::model::ModelError) -> PyErr {
        from_model_error(
            py,
            e,
            self.file.as_deref(),
            self.lines && self.text.is_some(),
        )
    }

    /// Marks the tables changed.
    fn changed(&mut self) {
        self.text = None;
        self.checked = None;
        self.lines = false;
    }

    fn name(&self) -> String {
        self.table
            .get("name")
            .and_then(Value::as_str)
            .unwrap_or("")
            .to_owned()
    }

    /// Appends `entry` to the array of tables `array` (`[[array]]`).
    fn push(&mut self, array: &str, entry: Table) {
        self.changed();
        let slot = self
            .table
            .entry(array)
            .or_insert_with(|| Value::Array(Vec::new()));
        if !matches!(slot, Value::Array(_)) {
            *slot = Value::Array(Vec::new());
        }
        if let Value::Array(a) = slot {
            a.push(Value::Table(entry));
        }
    }

    /// Sets keys of the table `name` (`[name]`).
    fn set_in(&mut self, name: &str, keys: Table) {
        self.changed();
        let slot = self
            .table
            .entry(name)
            .or_insert_with(|| Value::Table(Table::new()));
        if !matches!(slot, Value::Table(_)) {
            *slot = Value::Table(Table::new());
        }
        if let Value::Table(t) = slot {
            t.extend(keys);
        }
    }

    /// The key path of entry `array[next]`, for messages.
    fn next_entry(&self, array: &str) -> String {
        let n = self
            .table
            .get(array)
            .and_then(Value::as_array)
            .map_or(0, Vec::len);
        format!("{array}[{n}]")
    }
}

/// The values of a `[[load]]` or `[[distributed_load]]` call.
struct LoadValues<'a, 'py> {
    force: Option<&'a Bound<'py, PyAny>>,
    moment: Option<&'a Bound<'py, PyAny>>,
    time: Option<&'a Bound<'py, PyAny>>,
    follower: Option<&'a Bound<'py, PyAny>>,
    keys: Option<&'a Bound<'py, PyDict>>,
}

impl PyModel {
    /// Appends an entry of the array `array` whose `target_key` (node or
    /// beam) is `target`, with the load's values.
    fn push_load<'py>(
        slf: Bound<'py, Self>,
        (array, target_key, target): (&str, &str, &str),
        v: LoadValues<'_, 'py>,
    ) -> PyResult<Bound<'py, Self>> {
        let prefix = slf.borrow().next_entry(array);
        let entry = Entry::new(slf.py(), prefix)
            .text(target_key, target)
            .value("force", v.force)?
            .value("moment", v.moment)?
            .value("time", v.time)?
            .value("follower", v.follower)?
            .extra(v.keys)?;
        slf.borrow_mut().push(array, entry.table);
        Ok(slf)
    }
}

/// Builds a table from named values (None: left out) and extra keys.
struct Entry<'py> {
    prefix: String,
    table: Table,
    py: Python<'py>,
}

impl<'py> Entry<'py> {
    fn new(py: Python<'py>, prefix: String) -> Self {
        Self {
            prefix,
            table: Table::new(),
            py,
        }
    }

    fn key(&self, name: &str) -> String {
        format!("{}.{name}", self.prefix)
    }

    fn text(mut self, name: &str, value: &str) -> Self {
        self.table.insert(name.into(), Value::String(value.into()));
        self
    }

    fn value(mut self, name: &str, value: Option<&Bound<'py, PyAny>>) -> PyResult<Self> {
        if let Some(v) = value.filter(|v| !v.is_none()) {
            let key = self.key(name);
            self.table.insert(name.into(), to_toml(v, &key)?);
        }
        Ok(self)
    }

    fn extra(mut self, keys: Option<&Bound<'py, PyDict>>) -> PyResult<Self> {
        if let Some(d) = keys {
            for (k, v) in d.iter() {
                if v.is_none() {
                    continue;
                }
                let name: String = k.extract().map_err(|_| {
                    key_error(self.py, &self.prefix, "keyword names must be strings")
                })?;
                let key = self.key(&name);
                self.table.insert(name, to_toml(&v, &key)?);
            }
        }
        Ok(self)
    }
}

/// The value at `path` in `root`, if every segment exists (tables too).
fn navigate<'a>(root: &'a mut Table, path: &[Segment]) -> Option<&'a mut Value> {
    let (first, rest) = path.split_first()?;
    let Segment::Key(k) = first else { return None };
    let mut current = root.get_mut(k)?;
    for segment in rest {
        current = match (segment, current) {
            (Segment::Key(k), Value::Table(t)) => t.get_mut(k)?,
            (Segment::Key(k), Value::Array(entries)) => {
                let mut hits = entries
                    .iter_mut()
                    .filter(|e| e.get("name").and_then(Value::as_str) == Some(k.as_str()));
                let hit = hits.next()?;
                if hits.next().is_some() {
                    return None;
                }
                hit
            }
            (Segment::Index(i), Value::Array(entries)) => entries.get_mut(*i)?,
            _ => return None,
        };
    }
    Some(current)
}

/// Puts `value` at `path` in `root`: an existing value is replaced; a key
/// that is missing from an existing table is added. The error says what
/// exists instead (the messages of study keys).
fn put(root: &mut Table, path: &KeyPath, value: Value) -> Result<(), String> {
    if let Some(slot) = navigate(root, &path.segments) {
        *slot = value;
        return Ok(());
    }
    if let Some((Segment::Key(last), parent)) = path.segments.split_last() {
        if parent.is_empty() {
            root.insert(last.clone(), value);
            return Ok(());
        }
        if let Some(Value::Table(t)) = navigate(root, parent) {
            t.insert(last.clone(), value);
            return Ok(());
        }
    }
    let mut copy = root.clone();
    match lookup_mut(&mut copy, path) {
        Ok(_) => Err("names no single value".into()),
        Err(problem) => Err(problem),
    }
}

#[pymethods]
impl PyModel {
    /// A model named `name` written with builder calls (its result file is
    /// `<name>.h5`): `Model("arm").section(...).beam(...).support(...)`.
    /// Each call adds a model-file table with the same keys as a model file
    /// (docs/MODEL_FORMAT.md) and returns the model; the whole is checked
    /// by the model-file validation when it is first used (`check`, `run`,
    /// `Simulation`, `study`).
    #[new]
    fn new(name: &str) -> Self {
        let mut table = Table::new();
        table.insert("name".into(), Value::String(name.into()));
        Self {
            table,
            text: None,
            file: None,
            lines: false,
            checked: None,
        }
    }

    /// Reads and checks the model file at `path` (raises `ModelError` with
    /// the file, line and key of the first problem).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        let text = std::fs::read_to_string(&path).map_err(|e| {
            let err = flexmech::model::ModelError::new(
                &path,
                "",
                None,
                format!("cannot read the model file: {e}"),
            );
            from_model_error(py, &err, Some(&path), true)
        })?;
        Self::read(py, text, path)
    }

    /// Reads and checks model-file `text`; `path` names it in messages
    /// (default `<string>`).
    #[staticmethod]
    #[pyo3(signature = (text, path = None))]
    fn from_toml(py: Python<'_>, text: String, path: Option<PathBuf>) -> PyResult<Self> {
        Self::read(py, text, path.unwrap_or_else(|| PathBuf::from("<string>")))
    }

    /// The model as model-file text: the text it was read from while
    /// unchanged, else its tables written as TOML.
    fn to_toml(&self) -> String {
        self.text()
    }

    /// The model's tables as a dict (a copy).
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        to_python(py, &Value::Table(self.table.clone()))
    }

    /// The model's name (`name` key).
    #[getter(name)]
    fn get_name(&self) -> String {
        self.name()
    }

    /// The model file or text name it was read from (None when built in
    /// Python).
    #[getter]
    fn file(&self) -> Option<String> {
        self.file.as_ref().map(|f| f.display().to_string())
    }

    /// Sets the value at `key`, a study key path (`solver.dt`,
    /// `joint.screw.pitch` — the `[[joint]]` entry named `screw` —,
    /// `beam[0].elements`, `section.rod.EI[0]`, `gravity[2]`); a key missing
    /// from an existing table is added. A model that was valid must stay
    /// so: otherwise the change is undone and `ModelError` names the key.
    /// Returns the model.
    fn set<'py>(
        slf: Bound<'py, Self>,
        key: &str,
        value: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        let v = to_toml(value, key)?;
        let path = KeyPath::parse(key).map_err(|p| {
            key_error(
                py,
                key,
                &format!(
                    "the key {p}; keys look like solver.dt, joint.screw.pitch or beam[0].elements"
                ),
            )
        })?;
        {
            let mut m = slf.borrow_mut();
            let was_valid = m.checked.is_some() || m.validate(py, None).is_ok();
            let mut table = m.table.clone();
            put(&mut table, &path, v).map_err(|p| key_error(py, key, &p))?;
            let checked = if was_valid {
                Some(m.validate(py, Some(&table)).inspect_err(|e| {
                    let text = e.value(py).str().map(|s| s.to_string()).unwrap_or_default();
                    let _ = e
                        .value(py)
                        .setattr("args", (format!("set `{key}`: {text}"),));
                })?)
            } else {
                None
            };
            m.changed();
            m.table = table;
            m.checked = checked;
        }
        Ok(slf)
    }

    /// The value at `key` (a study key path, as for `set`).
    fn get<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        let path = KeyPath::parse(key).map_err(|p| key_error(py, key, &format!("the key {p}")))?;
        let mut table = self.table.clone();
        match navigate(&mut table, &path.segments) {
            Some(v) => to_python(py, v),
            None => {
                let problem = lookup_mut(&mut table, &path)
                    .err()
                    .unwrap_or_else(|| "is not a value".into());
                Err(key_error(py, key, &problem))
            }
        }
    }

    /// Checks the model as a model file is checked; returns it, or raises
    /// `ModelError`.
    fn check(mut slf: PyRefMut<'_, Self>) -> PyResult<PyRefMut<'_, Self>> {
        let py = slf.py();
        slf.checked(py)?;
        Ok(slf)
    }

    /// The same as `check` (the Rust builder's last call).
    fn build(slf: PyRefMut<'_, Self>) -> PyResult<PyRefMut<'_, Self>> {
        Self::check(slf)
    }

    /// A copy that changes independently.
    fn copy(&self) -> Self {
        self.clone()
    }

    fn __copy__(&self) -> Self {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    fn __repr__(&self) -> String {
        match &self.file {
            Some(f) => format!(
                "Model({:?}, file={:?})",
                self.name(),
                f.display().to_string()
            ),
            None => format!("Model({:?})", self.name()),
        }
    }

    /// Gravity's acceleration `g` (3 components).
    fn gravity<'py>(slf: Bound<'py, Self>, g: &Bound<'py, PyAny>) -> PyResult<Bound<'py, Self>> {
        let v = to_toml(g, "gravity")?;
        {
            let mut m = slf.borrow_mut();
            m.changed();
            m.table.insert("gravity".into(), v);
        }
        Ok(slf)
    }

    /// A `[[section]]`: stiffnesses and masses per unit length (`EA`,
    /// `GA = [GA2, GA3]`, `GJ`, `EI = [EI2, EI3]`, `rhoA`, `rhoJ`,
    /// `damping`), as in model files; other keys by name.
    #[pyo3(signature = (name, *, EA, GA, GJ, EI, rhoA = None, rhoJ = None, damping = None, **keys))]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn section<'py>(
        slf: Bound<'py, Self>,
        name: &str,
        EA: &Bound<'py, PyAny>,
        GA: &Bound<'py, PyAny>,
        GJ: &Bound<'py, PyAny>,
        EI: &Bound<'py, PyAny>,
        rhoA: Option<&Bound<'py, PyAny>>,
        rhoJ: Option<&Bound<'py, PyAny>>,
        damping: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let prefix = slf.borrow().next_entry("section");
        let entry = Entry::new(slf.py(), prefix)
            .text("name", name)
            .value("EA", Some(EA))?
            .value("GA", Some(GA))?
            .value("GJ", Some(GJ))?
            .value("EI", Some(EI))?
            .value("rhoA", rhoA)?
            .value("rhoJ", rhoJ)?
            .value("damping", damping)?
            .extra(keys)?;
        slf.borrow_mut().push("section", entry.table);
        Ok(slf)
    }

    /// A `[[beam]]` of `elements` elements of section `section`: straight
    /// from `start` to `end` (section axis `e2`) or along `arc` (a dict
    /// `start`, `center`, `normal`, `sweep`); its nodes are `name.start`,
    /// `name.1`, …, `name.end`.
    #[pyo3(signature = (name, section, *, elements, start = None, end = None, e2 = None, arc = None, nodes_per_element = None, **keys))]
    #[allow(clippy::too_many_arguments)]
    fn beam<'py>(
        slf: Bound<'py, Self>,
        name: &str,
        section: &str,
        elements: &Bound<'py, PyAny>,
        start: Option<&Bound<'py, PyAny>>,
        end: Option<&Bound<'py, PyAny>>,
        e2: Option<&Bound<'py, PyAny>>,
        arc: Option<&Bound<'py, PyAny>>,
        nodes_per_element: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let prefix = slf.borrow().next_entry("beam");
        let entry = Entry::new(slf.py(), prefix)
            .text("name", name)
            .text("section", section)
            .value("start", start)?
            .value("end", end)?
            .value("arc", arc)?
            .value("elements", Some(elements))?
            .value("nodes_per_element", nodes_per_element)?
            .value("e2", e2)?
            .extra(keys)?;
        slf.borrow_mut().push("beam", entry.table);
        Ok(slf)
    }

    /// A `[[support]]` holding `node`: `fixed` is `"all"`, DOF names
    /// separated by commas (`"ux, uy, rz"`) or a list of them.
    #[pyo3(signature = (node, fixed = None))]
    fn support<'py>(
        slf: Bound<'py, Self>,
        node: &str,
        fixed: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        let prefix = slf.borrow().next_entry("support");
        let fixed = match fixed {
            None => Value::String("all".into()),
            Some(f) => match f.cast::<PyString>() {
                Ok(s) if s.to_cow()?.trim() == "all" => Value::String("all".into()),
                Ok(s) => Value::Array(
                    s.to_cow()?
                        .split(',')
                        .map(|d| Value::String(d.trim().into()))
                        .collect(),
                ),
                Err(_) => to_toml(f, &format!("{prefix}.fixed"))?,
            },
        };
        let mut entry = Entry::new(py, prefix).text("node", node);
        entry.table.insert("fixed".into(), fixed);
        slf.borrow_mut().push("support", entry.table);
        Ok(slf)
    }

    /// A `[[joint]]` named `name` of kind `kind` (a registered joint type:
    /// `flexmech.joint_kinds()`) between `master` (a node or `"ground"`) and
    /// `slave`; its parameters as keywords (`axis=[0, 0, 1], pitch=0.1`), as
    /// a dict, or as model-file text (`"axis = [0, 0, 1]\npitch = 0.1"`).
    #[pyo3(signature = (name, kind, master, slave, params = None, **keys))]
    fn joint<'py>(
        slf: Bound<'py, Self>,
        name: &str,
        kind: &str,
        master: &str,
        slave: &str,
        params: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        let prefix = slf.borrow().next_entry("joint");
        let mut entry = Entry::new(py, prefix.clone())
            .text("name", name)
            .text("type", kind)
            .text("master", master)
            .text("slave", slave);
        match params {
            None => {}
            Some(p) if p.is_none() => {}
            Some(p) => {
                let table = if let Ok(s) = p.cast::<PyString>() {
                    toml::from_str::<Table>(&s.to_cow()?).map_err(|e| {
                        key_error(
                            py,
                            &prefix,
                            &format!(
                                "the parameters `{s}` are not model-file text: {}",
                                e.message().trim()
                            ),
                        )
                    })?
                } else if let Ok(d) = p.cast::<PyDict>() {
                    dict_to_table(d, &prefix)?
                } else {
                    return Err(key_error(
                        py,
                        &prefix,
                        "params must be model-file text or a dict",
                    ));
                };
                entry.table.extend(table);
            }
        }
        let entry = entry.extra(keys)?;
        slf.borrow_mut().push("joint", entry.table);
        Ok(slf)
    }

    /// A `[[load]]` on `node`: `force` and `moment` (global components),
    /// `time` (a number, `{"table": [[t, s], ...]}` or `{"expr": "..."}`),
    /// `follower`.
    #[pyo3(signature = (node, force = None, moment = None, *, time = None, follower = None, **keys))]
    fn nodal_load<'py>(
        slf: Bound<'py, Self>,
        node: &str,
        force: Option<&Bound<'py, PyAny>>,
        moment: Option<&Bound<'py, PyAny>>,
        time: Option<&Bound<'py, PyAny>>,
        follower: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let values = LoadValues {
            force,
            moment,
            time,
            follower,
            keys,
        };
        Self::push_load(slf, ("load", "node", node), values)
    }

    /// A `[[distributed_load]]` per unit length on beam `beam`.
    #[pyo3(signature = (beam, force = None, moment = None, *, time = None, follower = None, **keys))]
    fn distributed_load<'py>(
        slf: Bound<'py, Self>,
        beam: &str,
        force: Option<&Bound<'py, PyAny>>,
        moment: Option<&Bound<'py, PyAny>>,
        time: Option<&Bound<'py, PyAny>>,
        follower: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let values = LoadValues {
            force,
            moment,
            time,
            follower,
            keys,
        };
        Self::push_load(slf, ("distributed_load", "beam", beam), values)
    }

    /// A `[[prescribed]]` released angle of joint `joint`: an expression of
    /// `t` (text), a number, or a time-function dict (`{"table": ...}`).
    fn drive<'py>(
        slf: Bound<'py, Self>,
        joint: &str,
        angle: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, Self>> {
        let py = slf.py();
        let prefix = slf.borrow().next_entry("prescribed");
        let angle_value = match angle.cast::<PyString>() {
            Ok(s) => {
                let mut f = Table::new();
                f.insert("expr".into(), Value::String(s.to_cow()?.into()));
                Value::Table(f)
            }
            Err(_) => to_toml(angle, &format!("{prefix}.angle"))?,
        };
        let mut entry = Entry::new(py, prefix).text("joint", joint);
        entry.table.insert("angle".into(), angle_value);
        slf.borrow_mut().push("prescribed", entry.table);
        Ok(slf)
    }

    /// Any other entry of an array of tables (`"prescribed"`,
    /// `"rigid_body"`, `"initial_velocity"`, …) with its model-file keys.
    #[pyo3(signature = (array, **keys))]
    fn add<'py>(
        slf: Bound<'py, Self>,
        array: &str,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let prefix = slf.borrow().next_entry(array);
        let entry = Entry::new(slf.py(), prefix).extra(keys)?;
        slf.borrow_mut().push(array, entry.table);
        Ok(slf)
    }

    /// A `[[rigid_body]]` (a point mass without `inertia` and `offset`).
    #[pyo3(signature = (node, mass, *, inertia = None, offset = None, name = None))]
    fn rigid_body<'py>(
        slf: Bound<'py, Self>,
        node: &str,
        mass: &Bound<'py, PyAny>,
        inertia: Option<&Bound<'py, PyAny>>,
        offset: Option<&Bound<'py, PyAny>>,
        name: Option<&str>,
    ) -> PyResult<Bound<'py, Self>> {
        let prefix = slf.borrow().next_entry("rigid_body");
        let mut entry = Entry::new(slf.py(), prefix)
            .text("node", node)
            .value("mass", Some(mass))?
            .value("inertia", inertia)?
            .value("offset", offset)?;
        if let Some(n) = name {
            entry = entry.text("name", n);
        }
        slf.borrow_mut().push("rigid_body", entry.table);
        Ok(slf)
    }

    /// An `[[initial_velocity]]` field on `nodes` (a beam name or a list of
    /// node labels): `v = linear + angular × (x − origin)`.
    #[pyo3(signature = (nodes, *, linear = None, angular = None, origin = None))]
    fn initial_velocity<'py>(
        slf: Bound<'py, Self>,
        nodes: &Bound<'py, PyAny>,
        linear: Option<&Bound<'py, PyAny>>,
        angular: Option<&Bound<'py, PyAny>>,
        origin: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, Self>> {
        let prefix = slf.borrow().next_entry("initial_velocity");
        let entry = Entry::new(slf.py(), prefix)
            .value("nodes", Some(nodes))?
            .value("linear", linear)?
            .value("angular", angular)?
            .value("origin", origin)?;
        slf.borrow_mut().push("initial_velocity", entry.table);
        Ok(slf)
    }

    /// Statics in `load_steps` load steps; other `[solver]` keys by name
    /// (`control="arc-length"`).
    #[pyo3(signature = (load_steps, **keys))]
    fn statics<'py>(
        slf: Bound<'py, Self>,
        load_steps: &Bound<'py, PyAny>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let entry = Entry::new(slf.py(), "solver".into())
            .text("analysis", "static")
            .value("load_steps", Some(load_steps))?
            .extra(keys)?;
        slf.borrow_mut().set_in("solver", entry.table);
        Ok(slf)
    }

    /// Time integration with `integrator` (`"newmark"`,
    /// `"generalized-alpha"`, `"momentum"`, `"energy-momentum"`,
    /// `"energy-momentum-paper"`), steps of `dt` to `t_end`; other
    /// `[solver]` keys by name (`rho_inf=0.5`).
    #[pyo3(signature = (integrator, dt, t_end, **keys))]
    fn dynamic<'py>(
        slf: Bound<'py, Self>,
        integrator: &str,
        dt: &Bound<'py, PyAny>,
        t_end: &Bound<'py, PyAny>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        let entry = Entry::new(slf.py(), "solver".into())
            .text("analysis", "dynamic")
            .text("integrator", integrator)
            .value("dt", Some(dt))?
            .value("t_end", Some(t_end))?
            .extra(keys)?;
        slf.borrow_mut().set_in("solver", entry.table);
        Ok(slf)
    }

    /// The `modes` lowest vibration modes (`analysis = "modal"`): about the
    /// initial state, or about the static equilibrium of the model's loads
    /// and drivers; other `[solver]` keys by name (`mass="lumped"`,
    /// `rotation={"axis": [0, 0, 1], "rate": 30.0}`). Results under `/modes`.
    #[pyo3(signature = (modes, **keys))]
    fn modal<'py>(
        slf: Bound<'py, Self>,
        modes: &Bound<'py, PyAny>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        linearised(slf, "modal", modes, keys)
    }

    /// The `modes` lowest linear buckling load factors of the model's loads
    /// (`analysis = "buckling"`), with their modes under `/buckling`; other
    /// `[solver]` keys by name (`eigensolver="sparse"`).
    #[pyo3(signature = (modes, **keys))]
    fn buckling<'py>(
        slf: Bound<'py, Self>,
        modes: &Bound<'py, PyAny>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        linearised(slf, "buckling", modes, keys)
    }

    /// `[solver]` keys: `solver("tolerance", 1e-8)` or `solver(tolerance=1e-8)`.
    #[pyo3(signature = (key = None, value = None, **keys))]
    fn solver<'py>(
        slf: Bound<'py, Self>,
        key: Option<&str>,
        value: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        table_keys(slf, "solver", key, value, keys)
    }

    /// `[output]` keys: `output("every", 10)` or `output(resultants=True)`.
    #[pyo3(signature = (key = None, value = None, **keys))]
    fn output<'py>(
        slf: Bound<'py, Self>,
        key: Option<&str>,
        value: Option<&Bound<'py, PyAny>>,
        keys: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, Self>> {
        table_keys(slf, "output", key, value, keys)
    }

    /// Records the nodes `nodes` under `/nodes/<label>` of the result.
    #[pyo3(signature = (*nodes))]
    fn track<'py>(slf: Bound<'py, Self>, nodes: Vec<String>) -> PyResult<Bound<'py, Self>> {
        slf.borrow_mut().push_output("track", nodes);
        Ok(slf)
    }

    /// Writes the exact derivatives of the results with respect to the
    /// model values at `keys` (key paths, e.g. `"section.rod.EI[0]"`):
    /// `/sensitivity/<key>/...` of the result.
    #[pyo3(signature = (*keys))]
    fn sensitivity<'py>(slf: Bound<'py, Self>, keys: Vec<String>) -> PyResult<Bound<'py, Self>> {
        slf.borrow_mut().push_output("sensitivity", keys);
        Ok(slf)
    }
}

impl PyModel {
    /// Appends `items` to the list `list` of `[output]`.
    fn push_output(&mut self, list: &str, items: Vec<String>) {
        self.changed();
        let output = self
            .table
            .entry("output")
            .or_insert_with(|| Value::Table(Table::new()));
        if let Value::Table(o) = output {
            let entries = o.entry(list).or_insert_with(|| Value::Array(Vec::new()));
            if let Value::Array(a) = entries {
                a.extend(items.into_iter().map(Value::String));
            }
        }
    }
}

/// `[solver]` of a linearised `analysis` ("modal" or "buckling") with
/// `modes` and other keys.
fn linearised<'py>(
    slf: Bound<'py, PyModel>,
    analysis: &str,
    modes: &Bound<'py, PyAny>,
    keys: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyModel>> {
    let entry = Entry::new(slf.py(), "solver".into())
        .text("analysis", analysis)
        .value("modes", Some(modes))?
        .extra(keys)?;
    slf.borrow_mut().set_in("solver", entry.table);
    Ok(slf)
}

/// `[name]` keys from `key`/`value` and keywords.
fn table_keys<'py>(
    slf: Bound<'py, PyModel>,
    name: &str,
    key: Option<&str>,
    value: Option<&Bound<'py, PyAny>>,
    keys: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyModel>> {
    let py = slf.py();
    let mut entry = Entry::new(py, name.into());
    match (key, value) {
        (Some(k), Some(v)) => entry = entry.value(k, Some(v))?,
        (None, None) => {}
        (Some(k), None) => return Err(key_error(py, &format!("{name}.{k}"), "give a value")),
        (None, Some(_)) => return Err(key_error(py, name, "give the key of the value")),
    }
    let entry = entry.extra(keys)?;
    slf.borrow_mut().set_in(name, entry.table);
    Ok(slf)
}

/// The joint kinds models can name (flexmech's own).
#[pyfunction]
pub fn joint_kinds() -> Vec<&'static str> {
    registry().names().collect()
}
