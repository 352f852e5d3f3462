// `frenetic commonroad` under mpirun: file i runs on rank i % size (with the rank's own threads),
// and each rank sends its files' reports to rank 0 as exact JSON text, where they are put back
// in file order; rank 0 then prints what a single process prints.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "apps/commonroad_report.h"
#include "frenetic/status.h"
#include "frenetic/tune/cluster.h"

namespace frenetic::apps::commonroad_cli {

// Whether file `index` runs on this process.
bool RunsHere(int index, const tune::Cluster& cluster);

// The reports at `indices` of `reports` as text, and back into `reports` (which must hold every
// index). Exact: every number reads back to the same double (non-finite ones included).
std::string Serialise(const std::vector<FileReport>& reports, const std::vector<int>& indices);
Status Deserialise(std::string_view text, std::vector<FileReport>* reports);

// Collective. `reports` holds every file's slot, this rank's (RunsHere) filled: on rank 0 all of
// them are filled on return, from every rank; the other ranks' are left as they are. An error
// (on rank 0) when a rank's text does not read back.
Status GatherReports(const tune::Cluster& cluster, std::vector<FileReport>* reports);

}  // namespace frenetic::apps::commonroad_cli
