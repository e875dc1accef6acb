/** @file
 * sy_mediator.h — the one small interface between core and every back-end: mediator classes
 * (a vtable registered by name), render requests, RGBA float + depth layers, and reference-counted
 * contexts (back-end instance + its adapted scene) shared by every viewport that shows the same
 * scene with the same back-end.
 *
 * A mediator translates the core scene into its back-end's own scene and keeps it in sync from
 * change lists; it never reads the live sy_scene (the application may already be editing the next
 * frame). A back-end only ever sees "fill this rectangle of pixels for this camera".
 *

 * One header per concept, all included here: sy_layer.h (layers), sy_request.h (camera views
 * and render requests), sy_registry.h (mediator classes, capabilities, the registry), sy_context.h
 * (contexts and their pool).
 *
 * Ownership: layers are owned by whoever created them (sy_layer_create / sy_layer_destroy).
 * Contexts are reference counted; sy_context_pool owns a reference to each cached context.
 * Thread-safety: the registry is safe to use from any thread (mutex). A context and a pool are
 * single-threaded: sync and render of one context must not run concurrently. */
#ifndef SY_MEDIATOR_H
#define SY_MEDIATOR_H

#include "sy_context.h"
#include "sy_layer.h"
#include "sy_registry.h"
#include "sy_request.h"

#endif /* SY_MEDIATOR_H */
