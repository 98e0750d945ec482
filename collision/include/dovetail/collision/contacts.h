#pragma once
/// \file contacts.h
/// Contact patches of two intersecting or touching meshes.
///
/// Why: the polygon level answers which triangle pairs intersect; a grasp, a
/// snap-fit check or a report needs where the parts meet, in which direction
/// they would separate and whether they merely touch or interpenetrate. One
/// patch per connected contact region (not one point per triangle pair) keeps
/// the answer small and stable: a box resting on a box is one patch whatever
/// the triangulation. See docs/proximity.md, "Contacts".

#include <span>
#include <string_view>
#include <vector>

#include "dovetail/collision/collide.h"
#include "dovetail/collision/mesh.h"
#include "dovetail/collision/model.h"
#include "dovetail/collision/types.h"

namespace dovetail::collision {

/// Settings of a contact query. Lengths are in mesh units.
struct ContactRequest {
  /// A patch whose depth is at most this is `touching`, deeper ones are penetrating.
  Real touching_tolerance = 1e-6;
  /// Two triangles whose vertices all lie within this distance of the other's
  /// plane are treated as coplanar (face on face) and give an overlap polygon.
  /// Exactly coplanar triangles always are.
  Real coplanar_tolerance = 1e-9;
  /// Pieces of intersection closer than this belong to one patch. The
  /// distance actually used is at least 1e-9 times the coordinate magnitude
  /// (at least 1), so pieces that meet up to rounding are always joined.
  Real merge_distance = 0;
  /// Estimate each patch's depth (the dearest part of the query). False:
  /// depth 0 and `penetrating` false for every patch, and the patch's pairs
  /// are the intersecting pairs and nearly coplanar neighbours as usual.
  bool estimate_depth = true;
  /// Also look next to the intersecting pairs for faces that lie on each other
  /// within `coplanar_tolerance` but that the exact test separates by a
  /// rounding-size gap (a rotated part resting on another), so that a resting
  /// face gives one face patch. False: the patches are made of the
  /// intersecting pairs alone (cheaper when many pairs cross one plane).
  bool nearly_coplanar_pairs = true;
  /// Passed to the all-pairs query of the models' overload (CollideRequest::front).
  SeparationFront* front = nullptr;
};

/// How the surfaces meet in a patch.
enum class ContactKind {
  kFace,   ///< faces lie on each other with opposite normals: area > 0
  kCurve,  ///< surfaces cross or touch along segments: edge on face, edge on edge, or a
           ///< penetration curve; length > 0, area 0
  kPoint,  ///< isolated points only (vertex on face, crossing edges)
};

/// "face", "curve" or "point", for reports.
std::string_view contact_kind_name(ContactKind kind);

/// One connected region of contact, all in A's frame.
struct ContactPatch {
  /// Representative point: area centroid of a face patch, length-weighted
  /// centroid of the segments of a curve patch, mean of the points otherwise.
  Vec3 point = Vec3::Zero();
  /// Unit contact normal pointing from A to B: the direction B moves to separate.
  Vec3 normal = Vec3::UnitZ();
  Real area = 0;    ///< overlap area of opposed coplanar faces (0 unless kFace)
  Real length = 0;  ///< total length of the patch's segments
  /// Local penetration estimate (0 when touching): how deep either part
  /// reaches into the other near the patch. Into a closed part: the deepest
  /// vertex of the other inside it, in a region connected to the patch, or
  /// deeper point of an edge of the patch that crosses its surface, measured
  /// to its surface; into an open part: the deepest vertex behind
  /// its patch faces (docs/proximity.md, "Depth estimate").
  Real depth = 0;
  bool penetrating = false;  ///< depth > touching_tolerance
  ContactKind kind = ContactKind::kPoint;
  /// The patch's triangle pairs, sorted: the intersecting pairs it was built
  /// from, plus nearly coplanar face pairs (within coplanar_tolerance) next
  /// to them that the exact test separates by a few ulps.
  std::vector<TrianglePair> pairs;
};

/// Contact patches of meshes `a` and `b`, B at pose X_AB in A's frame, from
/// their intersecting triangle pairs: all of them, as CollisionModel::collide
/// with all_pairs reports them (any order, duplicates ignored); the depth
/// estimate relies on the list being complete. Patches are
/// ordered by their smallest pair, so the result is deterministic. Empty
/// when `pairs` is.
std::vector<ContactPatch> compute_contacts(const Mesh& a, const Mesh& b, const Transform& X_AB,
                                           std::span<const TrianglePair> pairs,
                                           const ContactRequest& request = {});

/// The same after running the all-pairs query `a.collide(b, X_AB)`.
std::vector<ContactPatch> compute_contacts(const CollisionModel& a, const CollisionModel& b,
                                           const Transform& X_AB,
                                           const ContactRequest& request = {});

}  // namespace dovetail::collision
