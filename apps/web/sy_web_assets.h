/* sy_web_assets.h — the page of sy web and its scripts, embedded at build time (apps/web/embed.cmake
 * writes sy_web_assets.c from the files in apps/web/assets/). Internal to the sy_web library.
 * The table is constant: any thread may read it. */
#ifndef SY_WEB_ASSETS_H
#define SY_WEB_ASSETS_H

#include <stddef.h>

/** One embedded file, served at its path with GET. */
typedef struct sy_web_asset {
    const char *path;           /**< "/index.html", "/view.js", ... */
    const char *content_type;   /**< from the file's extension */
    const unsigned char *bytes; /**< the file's bytes (static storage) */
    size_t len;                 /**< their count */
} sy_web_asset;

extern const sy_web_asset sy_web_assets[]; /**< every embedded file */
extern const size_t sy_web_asset_count;    /**< their count */

/** The asset served at path ("/" is "/index.html"); NULL when there is none. */
const sy_web_asset *sy_web_asset_find(const char *path);

#endif
