/* sy_web_assets.h — the page of sy web, embedded at build time (apps/web/embed.cmake writes
 * sy_web_assets.c from apps/web/assets/index.html). Internal to the sy_web library. */
#ifndef SY_WEB_ASSETS_H
#define SY_WEB_ASSETS_H

#include <stddef.h>

extern const unsigned char sy_web_asset_index_html[]; /**< the page's bytes */
extern const size_t sy_web_asset_index_html_len;      /**< their count */

#endif
