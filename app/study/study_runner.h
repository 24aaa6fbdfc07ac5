// nbvh study: trains every configuration of a sweep, renders it from every camera and measures what its
// accuracy costs (issue 11; paper §5, Figs. 6-8, Table 1). See app/README.md for what each row means.
#pragma once
#include "app/study/study_options.h"

namespace nbvh::app {

// Writes OUT_DIR/study.json and study.csv after the references and after each configuration (a run cut
// short keeps what it finished). Throws nbvh::Error on bad options or inputs, before any long work.
void run_study(const StudyOptions& options);

} // namespace nbvh::app
