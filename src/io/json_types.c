/* json_types.c: the constraint types of a particle config (json.h's jtype), in the order
 * w:save writes them and the reader reads them: "constraints" (distances, then bends), then
 * each type's own section. A new type: its json_NAME.c, its line here and in json.h */
#include "json.h"

const jtype *const jtypes[] = {
    &jt_distance, &jt_bend, &jt_volume, &jt_tet, &jt_shape_match, &jt_pressure, &jt_attach, &jt_grab, &jt_tether,
};
const int njtypes = (int)(sizeof jtypes / sizeof jtypes[0]);
_Static_assert(sizeof jtypes / sizeof jtypes[0] <= JT_MAX, "JT_MAX (json.h) is too small for the table");
