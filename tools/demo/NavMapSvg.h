#pragma once

// The top-down picture of a demo run: the final navmesh of the human profile, each polygon coloured by how
// many frames its tile took from being needed to its first publication, and the trails of some agents over
// the run. Standard library only, as the rest of the report.

#include "demo/DemoResult.h"

#include <string>

namespace cairn::demo
{

/// A self-contained SVG of inRun's navmesh map and agent trails, 800 px wide, north (+z) up; a "no data"
/// picture when the run has neither.
std::string SvgNavMap(const DemoRunResult& inRun);

} // namespace cairn::demo
