#pragma once
// The OBB tree is declared beside the AABB tree, its sibling reference hierarchy.
#include "polygon/aabb_tree.h"
