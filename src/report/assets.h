// The page's web assets (src/report/web/), embedded at build time by report.cmake.
#pragma once

#include <string_view>

namespace frenetic::report::internal {

// report.html with report.css and the script's parts (report.cmake's order) inlined;
// "@FRENETIC_DATA@" marks where the data goes. One page for drives and CommonRoad runs: the
// script tells them apart by the data's header (world "commonroad").
std::string_view PageTemplateText();

}  // namespace frenetic::report::internal
