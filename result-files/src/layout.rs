//! Names of everything in a result file: the public contract of
//! `MODEL_FORMAT.md`, "Result file (HDF5)". Never rename an entry here; add new
//! ones instead.
//!
//! Dataset paths are absolute (`/energy/kinetic`). Per-node and per-joint
//! datasets live below a group named after the label verbatim; build their
//! paths with [`node_path`] and [`joint_path`].

/// Root attribute: the model file text (TOML) the run was started from.
pub const ATTR_MODEL: &str = "model";
/// Root attribute: integrator name (`"static"` for statics).
pub const ATTR_INTEGRATOR: &str = "integrator";
/// Root attribute: version of the crate that wrote the file.
pub const ATTR_VERSION: &str = "version";
/// Root attribute: [`STATUS_RUNNING`], [`STATUS_COMPLETED`] or `"failed: <reason>"`.
pub const ATTR_STATUS: &str = "status";
/// Root attribute: wall-clock time of the run in seconds (written by `finish`).
pub const ATTR_WALL_TIME: &str = "wall_time_s";
/// Root attribute: the run's energy drift over every converged step
/// ([`super::merit`]).
pub const ATTR_ENERGY_DRIFT: &str = "energy_drift";
/// Root attribute: largest displacement of a tracked node over every
/// converged step ([`super::merit`]).
pub const ATTR_MAX_DISPLACEMENT: &str = "max_displacement";
/// Root attribute: Newton iterations of every converged step
/// ([`super::merit`]).
pub const ATTR_NEWTON_ITERATIONS: &str = "newton_iterations";
/// Root attribute: converged steps ([`super::merit`]).
pub const ATTR_STEPS: &str = "steps";
/// Group of the stress resultants (`[output] resultants = true`).
pub const RESULTANTS: &str = "/resultants";
/// T × G × 3: `N` at every Gauss point.
pub const RESULTANTS_FORCE: &str = "/resultants/force";
/// T × G × 3: `M` at every Gauss point.
pub const RESULTANTS_MOMENT: &str = "/resultants/moment";
/// G: each Gauss point's arc length from its beam's start.
pub const RESULTANTS_ARC_LENGTH: &str = "/resultants/arc_length";
/// Root attribute: warnings about a completed result (absent when none).
pub const ATTR_WARNINGS: &str = "warnings";
/// Root attribute: the git revision flexmech was built from (`+modified`
/// when the working tree had uncommitted changes; `unknown` outside git).
pub const ATTR_GIT_REVISION: &str = "git_revision";
/// Root attribute: when the file was created, UTC, ISO 8601.
pub const ATTR_CREATED: &str = "created";
/// Root attribute: the units of the numbers in the file.
pub const ATTR_UNITS: &str = "units";
/// Root attribute: the command line that made the run (when known).
pub const ATTR_COMMAND_LINE: &str = "command_line";
/// The text of [`ATTR_UNITS`].
pub const UNITS_NOTE: &str = "the model file's consistent units (e.g. m, kg, s, N, J); angles and \
                              rotation vectors in radians";
/// T×3 per joint: the force the joint exerts on its slave node (global).
pub const JOINT_REACTION_FORCE: &str = "reaction_force";
/// T×3 per joint: the moment the joint exerts on its slave node (global).
pub const JOINT_REACTION_MOMENT: &str = "reaction_moment";
/// `/supports`: one group per supported node (a fixed or prescribed DOF).
pub const SUPPORTS: &str = "/supports";

/// `/supports/<label>/<leaf>`.
pub fn support_path(label: &str, leaf: &str) -> String {
    format!("{SUPPORTS}/{label}/{leaf}")
}

/// `/mesh`: the mesh, written once.
pub const MESH: &str = "/mesh";
/// nodes (strings): every node's label, in `/configuration` order.
pub const MESH_NODE_LABELS: &str = "/mesh/node_labels";
/// Σ nodes per element (u64): the elements' nodes, element after element.
pub const MESH_ELEMENT_NODES: &str = "/mesh/element_nodes";
/// elements + 1 (u64): element `e` has nodes `element_nodes[offsets[e]..offsets[e+1]]`.
pub const MESH_ELEMENT_OFFSETS: &str = "/mesh/element_offsets";
/// beams (strings): the beams' names, in model order.
pub const MESH_BEAM_NAMES: &str = "/mesh/beam_names";
/// Σ nodes per beam (u64): the beams' nodes in order along each beam.
pub const MESH_BEAM_NODES: &str = "/mesh/beam_nodes";
/// beams + 1 (u64): beam `b` has nodes `beam_nodes[offsets[b]..offsets[b+1]]`.
pub const MESH_BEAM_OFFSETS: &str = "/mesh/beam_offsets";

/// nodes × 3 × 3 (extension): each node's initial triad `Λ₀`, row `k` the
/// director `e₍ₖ₊₁₎` (`e₁` along the beam, `e₂`, `e₃` spanning the section);
/// zeros for nodes on no beam. The current triad is `R Λ₀`, `R` from
/// `/configuration/quaternion`.
pub const MESH_NODE_DIRECTORS: &str = "/mesh/node_directors";

/// nodes × 3 (extension): each node's initial position, from which
/// displacements are measured.
pub const MESH_INITIAL_POSITION: &str = "/mesh/initial_position";

/// Root attribute of a continued run: the result file it continues.
pub const ATTR_RESTARTED_FROM: &str = "restarted_from";
/// Root attribute of a continued run: the time it continues from.
pub const ATTR_RESTART_TIME: &str = "restart_time";
/// Attribute on datasets and groups: a one-line human-readable meaning.
pub const ATTR_DESCRIPTION: &str = "description";
/// Attribute on `/nodes/<label>` (extension): the node index in the model.
pub const ATTR_NODE_INDEX: &str = "node_index";
/// Attribute on `/joints/<name>` (extension): the joint index in model order.
pub const ATTR_JOINT_INDEX: &str = "joint_index";
/// Attribute on `/joints/<name>` (extension): the joint's master node, an
/// index into `/configuration` (absent in files written before it).
pub const ATTR_JOINT_MASTER_NODE: &str = "master_node";
/// Attribute on `/joints/<name>` (extension): the joint's slave node, an
/// index into `/configuration` (absent in files written before it).
pub const ATTR_JOINT_SLAVE_NODE: &str = "slave_node";

/// `status` while the run is in progress (and after a crash).
pub const STATUS_RUNNING: &str = "running";
/// `status` of a run that reached its end.
pub const STATUS_COMPLETED: &str = "completed";
/// Prefix of the `status` of a run that stopped early.
pub const STATUS_FAILED_PREFIX: &str = "failed: ";

/// `status` text for a run that failed for `reason`: `"failed: <reason>"`.
pub fn failed_status(reason: &str) -> String {
    format!("{STATUS_FAILED_PREFIX}{reason}")
}

/// T: time (statics: load factor) of each stored step.
pub const TIME: &str = "/time";

/// Group of the energy datasets.
pub const ENERGY: &str = "/energy";
/// T: kinetic energy.
pub const ENERGY_KINETIC: &str = "/energy/kinetic";
/// T: strain energy.
pub const ENERGY_STRAIN: &str = "/energy/strain";
/// T: potential of gravity and dead loads.
pub const ENERGY_POTENTIAL: &str = "/energy/potential";
/// T: kinetic + strain + potential.
pub const ENERGY_TOTAL: &str = "/energy/total";
/// T: work done by driven joint coordinates and prescribed DOFs since t = 0.
pub const ENERGY_DRIVER_WORK: &str = "/energy/driver_work";
/// T: energy dissipated by structural damping since t = 0 (zero without
/// damping; included in `/energy/potential` and `/energy/total`).
pub const ENERGY_DISSIPATED: &str = "/energy/dissipated";

/// Group of the momentum datasets.
pub const MOMENTUM: &str = "/momentum";
/// T×3: total linear momentum.
pub const MOMENTUM_LINEAR: &str = "/momentum/linear";
/// T×3: total angular momentum about the origin.
pub const MOMENTUM_ANGULAR: &str = "/momentum/angular";

/// Group of the solver datasets.
pub const SOLVER: &str = "/solver";
/// T (u64): Newton iterations of the step.
pub const SOLVER_ITERATIONS: &str = "/solver/iterations";
/// T (u64): tangent factorisations of the step (*extension*; fewer than the
/// iterations with modified Newton).
pub const SOLVER_FACTORIZATIONS: &str = "/solver/factorizations";
/// T: step size actually used (after halvings).
pub const SOLVER_DT: &str = "/solver/dt";
/// T: final scaled residual norm.
pub const SOLVER_RESIDUAL: &str = "/solver/residual";
/// T: energy–momentum β (NaN for other integrators).
pub const SOLVER_BETA: &str = "/solver/beta";
/// Statics: negative eigenvalues of the converged tangent per step (`i64`).
pub const SOLVER_NEGATIVE_PIVOTS: &str = "/solver/negative_pivots";
/// Flat (extension): every step's Newton residual history, concatenated.
pub const SOLVER_NEWTON_RESIDUALS: &str = "/solver/newton_residuals";
/// T+1 (u64, extension): step k's history is
/// `newton_residuals[offsets[k]..offsets[k+1]]`; `offsets[0] = 0`.
pub const SOLVER_NEWTON_OFFSETS: &str = "/solver/newton_offsets";

/// Group holding one group per tracked node, named by its label.
pub const NODES: &str = "/nodes";
/// T×3 dataset in `/nodes/<label>`: position.
pub const NODE_POSITION: &str = "position";
/// T×3 dataset in `/nodes/<label>`: position − initial position.
pub const NODE_DISPLACEMENT: &str = "displacement";
/// T×3 dataset in `/nodes/<label>`: rotation vector of the node's triad, |ψ| ≤ π.
pub const NODE_ROTATION: &str = "rotation";

/// Group holding one group per joint, named by its name.
pub const JOINTS: &str = "/joints";
/// T dataset in `/joints/<name>`: released angle ψ.
pub const JOINT_ANGLE: &str = "angle";
/// T×3 dataset in `/joints/<name>`: released translation r_R in the master frame.
pub const JOINT_RELEASED_TRANSLATION: &str = "released_translation";
/// T dataset in `/joints/<name>`: constraint violation.
pub const JOINT_CONSTRAINT_ERROR: &str = "constraint_error";

/// Group of the full-configuration datasets.
pub const CONFIGURATION: &str = "/configuration";
/// T×nodes×3: every node's position.
pub const CONFIGURATION_POSITION: &str = "/configuration/position";
/// T×nodes×4: every node's triad as a unit quaternion (w, x, y, z).
pub const CONFIGURATION_QUATERNION: &str = "/configuration/quaternion";
/// T×nodes×3, dynamics only: every node's translational velocity.
pub const CONFIGURATION_VELOCITY: &str = "/configuration/velocity";
/// T×nodes×3, dynamics only: every node's angular velocity `ω = R W`
/// (spatial components).
pub const CONFIGURATION_ANGULAR_VELOCITY: &str = "/configuration/angular_velocity";

/// Path of the group of tracked node `label`: `/nodes/<label>`.
pub fn node_group(label: &str) -> String {
    format!("{NODES}/{label}")
}

/// Path of dataset `leaf` (e.g. [`NODE_POSITION`]) of tracked node `label`.
pub fn node_path(label: &str, leaf: &str) -> String {
    format!("{NODES}/{label}/{leaf}")
}

/// Path of the group of joint `name`: `/joints/<name>`.
pub fn joint_group(name: &str) -> String {
    format!("{JOINTS}/{name}")
}

/// Path of dataset `leaf` (e.g. [`JOINT_ANGLE`]) of joint `name`.
pub fn joint_path(name: &str, leaf: &str) -> String {
    format!("{JOINTS}/{name}/{leaf}")
}

/// `/sensitivity`: one group per `[output] sensitivity` key path, named
/// as written (`/sensitivity/section.rod.EI[0]`).
pub const SENSITIVITY: &str = "/sensitivity";
/// Vibration modes of `analysis = "modal"`.
pub const MODES: &str = "/modes";
/// Buckling modes of `analysis = "buckling"`.
pub const BUCKLING: &str = "/buckling";
/// Critical points located on a static path.
pub const STABILITY: &str = "/stability";
/// `/stability/critical_load_factor`: the located points' load factors.
pub const STABILITY_CRITICAL_LOAD_FACTOR: &str = "/stability/critical_load_factor";
/// Root attribute of a completed static path: why it ended (the load
/// factor reached, the arc-length budget, a `stop` of the model).
pub const ATTR_END_REASON: &str = "end_reason";

/// Path of the group of sensitivity key `key`: `/sensitivity/<key>`.
pub fn sensitivity_group(key: &str) -> String {
    format!("{SENSITIVITY}/{key}")
}

/// T×3: `d(displacement)/dp` of tracked node `label` with respect to the
/// model value at `key`: `/sensitivity/<key>/nodes/<label>/displacement`.
pub fn sensitivity_node_path(key: &str, label: &str) -> String {
    format!("{SENSITIVITY}/{key}{NODES}/{label}/{NODE_DISPLACEMENT}")
}

/// T: `d(total energy)/dp` with respect to the model value at `key`:
/// `/sensitivity/<key>/energy/total`.
pub fn sensitivity_energy_path(key: &str) -> String {
    format!("{SENSITIVITY}/{key}{ENERGY_TOTAL}")
}

/// Why `name` cannot be used verbatim as an HDF5 group name, if it cannot.
///
/// Labels such as `arm.end` or `post.3` are fine; `/` separates path
/// components, `.` alone means "this group", and HDF5 names are C strings.
pub fn invalid_name_reason(name: &str) -> Option<&'static str> {
    if name.is_empty() {
        Some("empty name")
    } else if name == "." {
        Some("\".\" denotes the group itself")
    } else if name.contains('/') {
        Some("contains '/', the HDF5 path separator")
    } else if name.contains('\0') {
        Some("contains a NUL character")
    } else {
        None
    }
}
