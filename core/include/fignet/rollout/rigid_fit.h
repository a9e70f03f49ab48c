// The rigid transform that best maps rest vertices onto predicted node positions (Kabsch with an
// SVD, reflections excluded): predicted meshes are replaced by rigid copies, so objects stay rigid.
#pragma once

#include "fignet/graph/scene.h"

namespace fignet {

// Least-squares rotation and translation taking `rest` (centre-of-mass frame) onto `moved`; the
// returned pose's position is where the rest origin (the centre of mass) lands.
Pose fit_rigid_transform(const Eigen::Ref<const Points>& rest,
                         const Eigen::Ref<const Points>& moved);

}  // namespace fignet
