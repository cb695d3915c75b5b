// SPDX-License-Identifier: MIT
// Simulation parameters shared by every solver: integrator, time step, forces, colliders.
// Units: metres, seconds, kilograms; z is up.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include "vkcloth/glm_abi.hpp"
#include "vkcloth/result.hpp"
#include "vkcloth/system.hpp"

namespace vkcloth {

/// Time integrators, each named for what it is (see docs/scene-format.md).
enum class Integrator : std::uint32_t {
  explicit_euler =
      0, ///< p += dt v_old; v += dt a   (the report's update as written; docs/model.md "Integrators")
  semi_implicit_euler = 1, ///< v += dt a; p += dt v_new   (what the report observed; the default)
  rk4 = 2,                 ///< classic 4-stage Runge-Kutta on (p, v)
  implicit_euler = 3,      ///< backward Euler (Baraff & Witkin 1998), linearised, solved by PCG
  vbd = 4, ///< backward Euler by vertex block descent (Chen et al. 2024): coloured Gauss-Seidel, one 3x3
           ///< Newton step per particle (docs/model.md "Vertex block descent")
};

/// What the last implicit solve achieved (zero for the explicit integrators).
struct SolveStats {
  std::uint32_t iterations = 0;       ///< CG iterations of the last (sub)step
  double residual = 0.0;              ///< |r| / |S b| at the end (0 when the right-hand side is 0)
  std::uint64_t total_iterations = 0; ///< CG iterations of every solve since the solver was made
  std::uint64_t solves = 0;           ///< implicit (sub)steps solved since the solver was made
  /// Mean CG iterations per solve (0 before the first).
  double mean_iterations() const { return solves ? double(total_iterations) / double(solves) : 0.0; }
};

/// Self-collision's neighbour lists (SelfCollision::skin > 0; CpuSolver::self_collision_stats).
struct SelfCollisionStats {
  std::uint64_t passes = 0;     ///< Jacobi passes since the solver was made
  std::uint64_t builds = 0;     ///< of those, the passes that built the lists first
  std::uint64_t candidates = 0; ///< list entries at the last build (each pair within thickness + skin twice)
  std::uint64_t overflowed = 0; ///< particles whose list overflowed at the last build (they walk the cells)
};

const char* to_string(Integrator integrator);
std::optional<Integrator> parse_integrator(std::string_view name);

struct ColliderPose; // below: a collider's pose for a per-frame update
class ColliderMesh;  // vkcloth/collider_mesh.hpp: a static triangle mesh and its bounding-volume hierarchy

struct ColliderPath;

/// A keyframed collider's pose at time t (docs/scene-format.md "keyframes"): the collider as it was
/// given (Collider::with_keyframes) turned by rotate_deg about its centre (R = Rz Ry Rx, x first) and
/// moved by translate.
struct ColliderKeyframe {
  double t = 0.0;             ///< s, >= 0, increasing along a path
  glm::dvec3 translate{0.0};  ///< m
  glm::dvec3 rotate_deg{0.0}; ///< degrees
  /// Reached by a jump at t (the previous key's pose held until then), which a cloth simulated in
  /// this collider's frame (SimParams::inertia) does not feel. Not on the first key.
  bool teleport = false;
};

/// A rigid jump (a teleport): x -> pivot + translation + rotation (x - pivot); velocities turn by
/// `rotation`.
struct RigidJump {
  glm::dvec3 pivot{0.0};
  glm::dvec3 translation{0.0};
  glm::dmat3 rotation{1.0};
  glm::dvec3 apply(glm::dvec3 x) const { return pivot + translation + rotation * (x - pivot); }
  /// Finite values and a rotation matrix (within 1e-6); the message names the field and the value.
  Result<void> validate() const;
};

/// A collider (docs/model.md "Collisions", docs/scene-format.md "colliders"): a shape, its friction and
/// its motion. Every shape has the report's semantics: within 2 eps of the surface the inward parts of
/// v and F go; after the update a point inside is put back at surface + eps.
///
/// The fields give the collider's pose now. A moving collider (linear_velocity, angular_velocity
/// about its centre) is advanced by the solver before every substep (posed_at(h): a substep meets it where
/// it is at the substep's end), so a
/// solver's params().colliders is always where its colliders are; a host animating a collider sets
/// its pose and velocity every frame (StepParams::colliders). Friction and the normal response are
/// relative to the surface's velocity.
struct Collider {
  enum class Type : std::uint32_t { plane = 0, sphere = 1, capsule = 2, box = 3, mesh = 4 };
  Type type = Type::plane;
  glm::dvec3 normal{0.0, 0.0, 1.0}; ///< plane: unit outward normal (normalised by validate())
  double offset = 0.0;              ///< plane: n.p on the surface
  glm::dvec3 center{0.0};           ///< sphere, box: centre; mesh: where the mesh's origin is
  double radius = 0.0;              ///< sphere, capsule
  glm::dvec3 a{0.0}, b{0.0};        ///< capsule: the segment's ends (a == b: a sphere)
  glm::dvec3 half_extents{0.0};     ///< box: > 0 each
  /// box, mesh: orientation, its columns the body's axes in the world (rotation_from_degrees).
  glm::dmat3 rotation{1.0};
  /// mesh: the triangles in the mesh's own frame (already scaled), with their hierarchy.
  std::shared_ptr<const ColliderMesh> mesh;
  double thickness = 0.0; ///< mesh: a point closer than this to a triangle is in contact (> 0)
  /// Coulomb friction: kinetic coefficient (>= 0; 0: frictionless, the report's model) ...
  double friction = 0.0;
  /// ... and static coefficient (>= friction; negative: the same as `friction`).
  double static_friction = -1.0;
  glm::dvec3 linear_velocity{0.0};  ///< m/s
  glm::dvec3 angular_velocity{0.0}; ///< rad/s about centre() (a plane takes linear velocity only)
  /// Keyframed motion (with_keyframes; null: none): posed_at follows the path from path_time, and the
  /// velocities are the path's over each advance. A host's with_pose ends it.
  std::shared_ptr<const ColliderPath> path;
  double path_time = 0.0; ///< s: the time along `path` the fields are posed at

  static Collider plane(glm::dvec3 normal, double offset);
  static Collider sphere(glm::dvec3 center, double radius);
  static Collider capsule(glm::dvec3 a, glm::dvec3 b, double radius);
  static Collider box(glm::dvec3 center, glm::dvec3 half_extents, glm::dmat3 rotation = glm::dmat3(1.0));
  static Collider triangle_mesh(std::shared_ptr<const ColliderMesh> mesh, glm::dvec3 origin,
                                glm::dmat3 rotation, double thickness);
  /// R = Rz Ry Rx from angles in degrees (x applied first: the mesh_transform convention).
  static glm::dmat3 rotation_from_degrees(glm::dvec3 degrees);

  /// The point angular_velocity turns about: the centre (capsule: the middle of a b; plane: the
  /// point of the plane nearest the origin).
  glm::dvec3 centre() const;
  /// static_friction, or friction when static_friction < 0.
  double static_coefficient() const { return static_friction < 0.0 ? friction : static_friction; }
  bool moving() const {
    return linear_velocity != glm::dvec3(0.0) || angular_velocity != glm::dvec3(0.0) || path != nullptr;
  }
  /// This collider `seconds` later: moved by linear_velocity * seconds and turned by angular_velocity
  /// * seconds about centre() (Rodrigues, in double); velocities and friction unchanged. A keyframed
  /// one takes its path's pose at path_time + seconds, and for velocities the path's motion over
  /// those seconds (the translation's change and the turn, each divided by `seconds`).
  Collider posed_at(double seconds) const;
  /// This collider moved along keyframes: at time t it is this collider turned by the pose's rotation
  /// about centre() and moved by its translation; between keys the translation is linear and the
  /// rotation a slerp; before the first key and past the last the pose holds. Returned posed at t = 0,
  /// at rest. The keys need t >= 0, strictly increasing, finite values (the message names
  /// keyframes[k] and the value); linear_velocity and angular_velocity must be zero.
  Result<Collider> with_keyframes(std::vector<ColliderKeyframe> keys) const;
  /// This collider moved to `pose` (ColliderPose says what each field sets); shape, friction and
  /// the rest unchanged. Not validated: ColliderPose::validate and SimParams::validate do that.
  Collider with_pose(const ColliderPose& pose) const;
};

/// A keyframed collider's path (Collider::with_keyframes): its keys and the collider they move.
struct ColliderPath {
  std::vector<ColliderKeyframe> keys;
  Collider base; ///< the collider at translate 0, rotate 0 (no path of its own)
  /// The translation and rotation at time t (held before the first key and past the last, and
  /// before a teleport key).
  void pose(double t, glm::dvec3& translate, glm::dmat3& rotation) const;
  /// Whether a teleport key lies in (t0, t1]: then `jump` is its jump (about the collider's centre
  /// before it) and `at` its time.
  bool jump_between(double t0, double t1, RigidJump& jump, double& at) const;
  /// `base` at the pose of time t (velocities zero).
  Collider at(double t) const;
};

/// A collider's pose for a per-frame update that keeps everything else (shape, size, friction,
/// thickness, mesh): ClothWorld::set_collider_pose and CpuWorld::set_collider_pose, or
/// Collider::with_pose. `position` is where centre() goes (sphere, box: centre; mesh: its origin;
/// capsule: the middle of a b; plane: any point of the plane). `rotation`, when given, is the body's
/// orientation, its columns the body's axes in the world: box and mesh take it as theirs; a
/// capsule's axis (a to b) and a plane's normal become its third column (their lengths kept); a
/// sphere ignores it. Without it the collider keeps its orientation. The velocities replace the
/// collider's (a plane takes linear velocity only, as always).
struct ColliderPose {
  glm::dvec3 position{0.0};
  std::optional<glm::dmat3> rotation;
  glm::dvec3 linear_velocity{0.0};  ///< m/s
  glm::dvec3 angular_velocity{0.0}; ///< rad/s about `position`

  /// Finite values and a rotation matrix (orthonormal, determinant 1, within 1e-6); the message
  /// names the field and the value.
  Result<void> validate() const;
};

/// Wind F = Kw <n, u_w> n on each cloth vertex, n its unit normal, u_w the unit wind direction.
struct Wind {
  double strength = 0.0;               ///< Kw
  glm::dvec3 direction{1.0, 0.0, 0.0}; ///< normalised by validate()
};

/// Stretch control (docs/model.md "Stretch control"), applied after each (sub)step's update: off by
/// default (the report's model). Provot's strain limiting projects every structural spring longer
/// than (1 + max_strain) L0 back to that length, `iterations` sweeps over the springs in colour
/// order (Gauss-Seidel, each colour a set of springs that share no particle); tethers (long-range
/// attachments, Kim, Chentanez and Mueller 2012) keep each particle within (1 + max_strain) of its
/// rest distance to the pinned particles it hangs from (up to 4, nearest first); the fast
/// projection (Goldenthal et al. 2007, after the tethers) solves for every structural spring over
/// the limit at once, Newton iterations of a CG, until each is within 1e-4 of it. The position
/// changes update the velocities (v += dx / dt); the colliders' projection follows.
struct StretchLimit {
  enum class Method : std::uint32_t { off = 0, tethers = 1, provot = 2, both = 3, projection = 4 };
  /// How a tether's rest length is measured in the rest state: straight, or along the cloth.
  enum class TetherDistance : std::uint32_t { euclidean = 0, geodesic = 1 };
  /// The order of Provot's sweeps (docs/model.md "Stretch control"): colour by colour (each link of a
  /// colour at once), or along chains, a grid's rows then its columns, each link after the one before
  /// it and back, so that one sweep carries a correction along a whole row (grids only).
  enum class SweepOrder : std::uint32_t { colours = 0, chains = 1 };
  Method method = Method::off;
  double max_strain = 0.1; ///< > 0: the largest allowed (|u| - L0) / L0
  /// 1..100 per substep: Provot sweeps, or (projection) the most Newton iterations.
  std::uint32_t iterations = 4;
  TetherDistance tether_distance = TetherDistance::euclidean;
  SweepOrder order = SweepOrder::colours; ///< Provot's sweeps (provot, both)

  bool provot() const { return method == Method::provot || method == Method::both; }
  bool chains() const { return provot() && order == SweepOrder::chains; }
  bool tethers() const {
    return method == Method::tethers || method == Method::both || method == Method::projection;
  }
  bool projection() const { return method == Method::projection; }
  bool enabled() const { return method != Method::off; }
};

const char* to_string(StretchLimit::Method method);
std::optional<StretchLimit::Method> parse_stretch_method(std::string_view name);
const char* to_string(StretchLimit::TetherDistance distance);
std::optional<StretchLimit::TetherDistance> parse_tether_distance(std::string_view name);
const char* to_string(StretchLimit::SweepOrder order);
std::optional<StretchLimit::SweepOrder> parse_sweep_order(std::string_view name);

/// Self-collision (docs/model.md "Self-collision"): off by default (the report's model). After each
/// substep's update (and stretch control), particles closer than `thickness` to each other are
/// pushed apart to that distance, unless they were already that close in the rest state (NvCloth's
/// rest-position filter: neighbours joined by short springs never collide). Pairs come from a
/// spatial hash of cells `thickness` wide, rebuilt every substep; `iterations` Jacobi passes each
/// move every particle by the mean of its pairs' corrections (mass-weighted, Coulomb friction on the
/// relative tangential velocity), and the moves update the velocities (v += dx / h). The colliders'
/// projection follows. Check a thickness against a cloth with check_self_collision().
struct SelfCollision {
  bool enabled = false;
  double thickness = 0.01;      ///< m, > 0: the distance kept between particles not that close at rest
  double friction = 0.2;        ///< >= 0: Coulomb coefficient between touching layers
  std::uint32_t iterations = 1; ///< 1..16 Jacobi passes per substep
  /// m, >= 0: 0 walks the hash's cells in every pass; > 0 keeps a neighbour list of the pairs within
  /// thickness + skin, rebuilt only when some particle has moved more than skin / 2 since
  /// (docs/model.md "Self-collision"; the same pairs, found less often).
  double skin = 0.0;
  /// N/m, >= 0: with integrator vbd, > 0 makes each pair a contact energy (k / 2) (t - d)^2 in the
  /// vertex steps of every sweep (it needs a skin: the steps read the neighbour lists) instead of the
  /// passes after the step; the other integrators keep the passes (docs/model.md "Self-collision").
  double stiffness = 0.0;
};

/// Particles that follow a collider (docs/model.md "Attachments"): particle particles[i]'s target
/// is the point offsets[i] of the collider's frame (centre() and `rotation`, as posed at each
/// substep's end), moving with the collider's velocity there. A pinned particle is put on its target
/// before each substep; a free one is brought back within `max_distance` of it after each substep
/// (0: onto it), which is how a particle is attached at run time and released (set_params without it).
struct Attachment {
  std::uint32_t collider = 0;           ///< index in SimParams::colliders (not a plane: it has no frame)
  std::vector<std::uint32_t> particles; ///< the cloth's particles, each in one attachment at most
  std::vector<glm::dvec3> offsets;      ///< one per particle, in the collider's frame (m)
  double max_distance = 0.0;            ///< m, >= 0: how far a free particle may stray (pinned: 0)

  /// The attachment of `particles` to `collider` (colliders[index]) that keeps them where
  /// `positions` (world, indexed by particle) puts them relative to the collider's pose now.
  /// ErrorCode::invalid_argument for a plane, a particle past `positions` or a negative distance.
  static Result<Attachment> at_rest(const Collider& collider, std::uint32_t index,
                                    std::vector<std::uint32_t> particles,
                                    const std::vector<glm::dvec3>& positions, double max_distance = 0.0);
};

/// A host's per-frame target for one particle (CpuSolver::set_pin_targets, the worlds'
/// set_pin_targets): reached at the next step's end, interpolated linearly across its substeps from
/// the particle's previous host target (a new one is reached at the first substep), and held after.
/// A pinned particle sits on it; a free one is held within `max_distance` of it (0: on it).
struct PinTarget {
  std::uint32_t particle = 0;
  glm::dvec3 position{0.0};
  double max_distance = 0.0; ///< m, >= 0
};

/// The frame a cloth is simulated in (docs/model.md "Inertia and teleport"; NvCloth's inertia scales):
/// a collider's, or a host transform. The cloth feels `linear` of the frame's linear acceleration and
/// `angular` of its angular motion (its angular acceleration, centrifugal and Coriolis parts); the
/// rest carries it along with the frame. A teleport of the frame (a keyframe's `teleport`, or the
/// solvers' teleport()) moves the cloth with it, unfelt. Off by default: world space.
struct Inertia {
  std::optional<std::uint32_t> collider; ///< index in SimParams::colliders (not a plane)
  /// ... or (not with `collider`) a host transform: its origin (`position`), `rotation` (none:
  /// identity) and velocities now, advanced by those velocities over the substeps as a moving
  /// collider is; a host sets it every frame (set_params, like a collider's pose).
  std::optional<ColliderPose> frame;
  double linear = 1.0;  ///< 0..1 (1: world space, 0: carried rigidly)
  double angular = 1.0; ///< 0..1
  bool enabled() const { return collider.has_value() || frame.has_value(); }
};

struct SimParams {
  Integrator integrator = Integrator::semi_implicit_euler;
  double dt = 0.02;
  /// One step = `substeps` substeps of dt / substeps (every integrator); time advances by dt.
  std::uint32_t substeps = 1;
  /// implicit_euler: CG stops when |r| <= cg_tolerance |S b| (relative residual) ...
  double cg_tolerance = 1e-6;
  /// ... or after this many iterations (then the step uses the last iterate).
  std::uint32_t cg_max_iterations = 200;
  /// vbd: Gauss-Seidel sweeps over the colours per substep (1..1000; docs/model.md "Vertex block
  /// descent", docs/performance.md for the default's cost and quality).
  std::uint32_t vbd_iterations = 5;
  glm::dvec3 gravity{0.0, 0.0, -9.81};
  /// Fluid damping mu (1/s): the force -mu m v. With m = 1 it is the report's -mu v; on a cloth
  /// it is the (1 - dt mu) velocity factor (docs/model.md "Forces").
  double damping = 0.5;
  Wind wind;
  std::vector<Collider> colliders;
  /// Projection distance eps: a particle found inside a collider is put back at surface + eps.
  /// A particle closer than 2 eps to a surface is "in contact" (its inward v and F are removed).
  double contact_epsilon = 1e-3;
  /// Remove only the parts of v and F that point INTO a collider (the default; docs/model.md "Collisions").
  /// False removes the whole normal part, the variant of the report's Figure 12 where the cloth sticks.
  bool contact_inward_only = true;
  /// A position with a coordinate |x_i| > this, or a non-finite position or velocity, is a blow-up
  /// (docs/model.md "Divergence").
  double divergence_limit = 1e4;
  StretchLimit stretch_limit;   ///< off by default
  SelfCollision self_collision; ///< off by default
  /// Particles that follow colliders (none by default). Their indices are checked against the cloth
  /// by the solvers (an index past it, or a particle in two attachments, is an error).
  std::vector<Attachment> attachments;
  Inertia inertia; ///< off by default (world space)

  /// Checks every field (finite, in range) and normalises directions. The message names the field.
  Result<void> validate();
};

/// A self-collision thickness against a cloth's spring lengths (structural springs; all springs
/// when it has none): an error (ErrorCode::invalid_argument naming self_collision.thickness) when it
/// is more than 10 x their mean rest length, since every particle would then touch most of the
/// cloth; otherwise the warnings: a thickness below half the smallest rest length (a triangle can
/// then pass between two particles), else below the largest circumradius of the cloth's triangles (a
/// particle can then cross a triangle's middle unseen). Nothing to check when self-collision is off.
Result<std::vector<std::string>> check_self_collision(const SelfCollision& self,
                                                      const ParticleSystem& system);

/// The attachments' particles against a cloth of `particles` particles: each index in it, and each
/// particle in one attachment at most (the solvers check this too; a scene loader, earlier). The
/// message names the entry (attachments[a].particles[i]) and the particle.
Result<void> check_attachments(const SimParams& params, std::size_t particles);

/// `params` with colliders[collider] moved to `pose` (Collider::with_pose), what the worlds'
/// set_collider_pose apply. ErrorCode::invalid_argument for an index past the list (the message
/// names it and the list's size) or a bad pose (ColliderPose::validate); the result is validated
/// by the solvers as any SimParams.
Result<SimParams> with_collider_pose(SimParams params, std::size_t collider, const ColliderPose& pose);

/// What a host changes every frame (its frame time, its wind, its animated colliders), applied
/// from the next recorded step: GpuSolver::record_steps(cmd, steps, step), ClothWorld::
/// set_step_params, or applied_to() + CpuSolver::set_params. The GPU backend records these values
/// into the command buffer (vkCmdUpdateBuffer), so a host with several frames in flight may change
/// them every frame without waiting. An empty field keeps the current value.
struct StepParams {
  std::optional<double> dt;
  std::optional<glm::dvec3> gravity;
  std::optional<Wind> wind;
  /// The whole collider list (e.g. the same colliders at this frame's positions).
  std::optional<std::vector<Collider>> colliders;

  /// `params` with the fields set here replaced (not validated: SimParams::validate does that).
  SimParams applied_to(SimParams params) const;
};

} // namespace vkcloth
