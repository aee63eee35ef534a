/* input.h: live input as a test. The viewer (cli/view.c) does every grab, move and release
 * through these functions, so each one is both done on the world and logged with the frame
 * it happened after; `--record-input FILE` saves the log as JSON and `wobble run --replay
 * FILE` applies it headless at the same frames (a frame hook), so the run ends with the
 * same w:hash() as the live one.
 *
 * Frames: an event logged with frame F was done after the world's frame F finished (in an
 * after-frame hook, wb_rt_after_frame), before frame F+1 starts; F >= 1. Worlds: `world` is
 * the 1-based ordinal of the world among the distinct worlds that finished a frame in this
 * run, in the order each finished its first frame (nearly always 1). Grabs are named in the
 * log by their 1-based ordinal among the log's grab events, not by wb_grab_id.
 *
 * The file (JSON, written with cJSON):
 *   { "format": "wobble-input", "version": 1, "scene": "scripts/x.lua",
 *     "events": [ { "frame": 12, "world": 1, "type": "grab", "particle": 37,
 *                   "target": [x, y, z], "compliance": 0 },
 *                 { "frame": 13, "world": 1, "type": "move", "grab": 1, "target": [x, y, z] },
 *                 { "frame": 30, "world": 1, "type": "release", "grab": 1 } ] }
 * particle ids are 1-based as in Lua; numbers are written with %.17g so they round-trip. */
#ifndef WBL_INPUT_H
#define WBL_INPUT_H

#include <lua.h>
#include <stdbool.h>
#include <stddef.h>

#include "wobble.h"

typedef struct wbl_input_log wbl_input_log;

/* ---- recording (the viewer) ---------------------------------------------------------- */
wbl_input_log *wbl_input_log_create(void);          /* NULL when out of memory */
void wbl_input_log_destroy(wbl_input_log *log);     /* NULL is fine */
void wbl_input_log_clear(wbl_input_log *log);       /* the scene restarted: drop what was logged */
/* do it on w and log it (frame = wb_world_frame(w) now, world = that ordinal); false with a
 * message when the world refuses (the particle id is bad, ...) and then nothing is logged.
 * A grab before the world's first frame is refused (no frame to replay it after); a move
 * or release of a grab that is no longer valid does nothing, and one of a grab the log
 * did not make (the script's own) is done but not logged. log may be NULL (not logged). */
bool wbl_input_grab(wbl_input_log *log, wb_world *w, int world, int32_t particle, const wb_real target[3],
                    wb_real compliance, wb_grab_id *out, char *err, size_t n);
void wbl_input_move(wbl_input_log *log, wb_world *w, int world, wb_grab_id g, const wb_real target[3]);
void wbl_input_release(wbl_input_log *log, wb_world *w, int world, wb_grab_id g);
int64_t wbl_input_log_events(const wbl_input_log *log);
bool wbl_input_log_save(const wbl_input_log *log, const char *path, const char *scene, char *err, size_t n);
/* the ordinal (1-based) of the world at index, as the log names worlds: a world is
 * numbered the first time this is asked about it, so call it after every frame of every
 * world (from a frame hook, as the replay does), not only when there is input */
int wbl_input_world(lua_State *L, int index);

/* ---- replay (`wobble run --replay FILE`) --------------------------------------------- */
/* read FILE (errors name file:line:col and the key path, exit 2) and register a frame hook
 * on L that applies each event after its world's frame; call before the script runs */
bool wbl_replay_begin(lua_State *L, const char *path, char *err, size_t n);
/* after the script: false with a message when events were left unapplied (the scene ended
 * before their frame, or it differs from the one recorded) */
bool wbl_replay_end(lua_State *L, char *err, size_t n);

#endif
