/* sy_mediator_nrm.h — the mediator of the "normals" test back-end (tests/backends/normals): the
 * shared scene mirror (sy_mirror.h) feeds its meshes and instances; renders are the world-space
 * geometric normal as (n + 1) / 2 with depth. An analysis back-end (SY_CAP_ANALYSIS): left out of
 * comparisons of looks and of the demo.
 * Added to the build by one line (sy_add_mediator in tests/CMakeLists.txt) and nothing outside its
 * own folders: the proof that a new back-end needs no change elsewhere (issue 16).
 * Thread-safety: like every mediator, one context at a time. */
#ifndef SY_MEDIATOR_NRM_H
#define SY_MEDIATOR_NRM_H

#include "sy_mediator.h"

sy_result sy_mediator_nrm_register(sy_error *err);

#endif /* SY_MEDIATOR_NRM_H */
