/* fuzz_web_message.c — libFuzzer target for sy web's WebSocket input messages
 * (sy_web_parse_input): each input is one text message as the server receives it (at most the
 * documented 4 KiB). Any result code is fine; crashes and sanitizer reports are not. */
#include "sy_web_check.h"

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size);

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    sy_web_input in;
    sy_web_parse_input((const char *)data, size, &in, NULL);
    return 0;
}
