// The page's web assets (src/report/web/), embedded at build time by report.cmake.
#pragma once

#include <string_view>

namespace frenetic::report::internal {

// report.html with report.css and report.js inlined; "@FRENETIC_DATA@" marks where the data goes.
// report.js's CommonRoad parts (lines between "//@commonroad" and "//@end", or "//@else" whose
// lines up to "//@end" stand for them in a drive's page) are left out of PageTemplateText and
// kept in CommonRoadPageTemplateText; the marker lines are in neither.
std::string_view PageTemplateText();
std::string_view CommonRoadPageTemplateText();

}  // namespace frenetic::report::internal
