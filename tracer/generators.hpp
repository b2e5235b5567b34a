// Built-in scenes: re-creations of Eric Haines' Standard Procedural Databases
// (SPD 3.14) generators, plus the named scenes of the VM_pRAY paper. For the
// same size a generator gives the same camera, lights, materials and geometry
// (counts and bounding box) as the SPD program's NFF output.
//
// Spec grammar:  NAME[:SIZE][:tRES]
//   NAME  teapot tetra mount rings balls gears tree   (SPD generators)
//         mountain rings4 tetra9 tetra10             (the paper's scenes; no size)
//   SIZE  the SPD size factor (default: the SPD program's default, teapot 8)
//   tRES  tessellate spheres and cones into triangles at resolution RES, as
//         SPD's "-t RES" does (see tessellate.hpp)
// The paper's "Teapot" (~3 754 polygons) is teapot:8 (4 096; size 7 gives
// 3 129, and no size gives 3 754 exactly).
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "tracer/scene.hpp"

namespace tracer {

struct BuiltinScene {
  std::string name;         // as written in a spec, e.g. "mount" or "mountain"
  std::string description;  // one line, for a list of the scenes
};

// Called with the scene and the resolution before a spec's tRES tessellates
// it, so that a caller may refuse a tessellation too large for it (by
// throwing) before it is made.
using TessellationCheck = std::function<void(const Scene& scene, int resolution)>;

// Throws std::invalid_argument naming the spec for an unknown name, a size
// out of range or a malformed spec.
Scene generate_scene(std::string_view spec, const TessellationCheck& before_tessellating = {});

// Every accepted NAME with a one-line description, in the order to list them.
std::vector<BuiltinScene> builtin_scenes();

// Each generator, for callers that want one directly (sizes as in the spec;
// they throw std::invalid_argument when the size is out of range).
Scene generate_teapot(int size);
Scene generate_tetra(int size);
Scene generate_mount(int size);
Scene generate_rings(int size);
Scene generate_balls(int size);
Scene generate_gears(int size);
Scene generate_tree(int size);

}  // namespace tracer
