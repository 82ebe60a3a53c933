// gr_keyframes.h: a solved gait as MuJoCo keyframes, for stock MuJoCo and its viewer
// (`mujoco-simulate`, Debian libmujoco-samples).
//
// The exported file is a small MJCF:
//   <mujoco model="gaitsim export ...">
//     <include file="REL/PATH/TO/MODEL.xml"/>
//     <keyframe>
//       <key name="gait_000" time="T" qpos="..." qvel="..." act="..."/>   one per states.sto row
//     </keyframe>
//   </mujoco>
// It includes the model instead of copying it, so the model stays one file and the export is a
// few kilobytes per frame. The include path is relative to the exported file's folder, because
// MuJoCo 2.2.2 prefixes the including file's folder to every include path (an absolute path
// fails with XML_ERROR_FILE_NOT_FOUND). Moving the exported file without the model therefore
// breaks it. The bundled models name no asset files; a model with meshes or textures given by
// relative paths is untested here (MuJoCo resolves asset paths from the top-level file's folder,
// so they may need a meshdir that works from there). The model's own keyframes come first,
// so the gait's keys start at index nkey of the model; find them by name ("gait_NNN").
//
// Each key: time = the row's time (s); qpos = every hinge/slide coordinate of the row (states.sto
// holds degrees when inDegrees=yes; keys hold radians and metres), other qpos entries qpos0;
// qvel = the "<joint>_u" speeds where states.sto has them, else 0; act = the
// "<actuator>.activation" columns, else 0. Numbers are written with 17 significant digits, so
// stock MuJoCo reads back the same doubles. Elastic-tendon states (gaitsim's userdata) have no
// keyframe field and are not exported.
//
// Errors: functions return 0 on success and -1 on failure with one line "CONTEXT: reason" in err
// (errsz bytes). Nothing is printed and nothing exits.
#ifndef GAITSIM_RENDER_GR_KEYFRAMES_H_
#define GAITSIM_RENDER_GR_KEYFRAMES_H_

#include <mujoco/mujoco.h>

// What an export wrote.
typedef struct grKeyframesInfo_ {
  int nkey;          // keyframes written, one per states.sto row  (count)
  int first_key;     // index of the first gait key in the exported model (the model's nkey)
  int nq_found;      // coordinates taken from states.sto           (count, of nq)
  int nv_found;      // speeds taken from states.sto, others 0       (count, of nv)
  int na_found;      // activations taken from states.sto, others 0  (count, of na)
  char include[4096];  // include path written, relative to the exported file's folder
} grKeyframesInfo;

// Path of `target` relative to the folder `from_dir` (both must exist; symbolic links resolved),
// e.g. "../../mjmodels/gait2d.xml", into out (n bytes).
int gr_keyframes_relative_path(const char* target, const char* from_dir, char* out, int n,
                               char* err, int errsz);

// Export states_path (a solution's states.sto) on model m, loaded from model_path, to out_path.
// Creates out_path's folder when missing. The file is written atomically (io/gs_atomic.h) and,
// before it replaces anything, compiled by stock MuJoCo (mj_loadXML, no gaitsim callbacks) and
// checked to hold the model's degrees of freedom and nkey + rows keys; a file that would not
// load is never published. Every hinge/slide coordinate of m must have a column; an out_path
// that is the model file itself is refused. info may be NULL.
int gr_keyframes_export(const mjModel* m, const char* model_path, const char* states_path,
                        const char* out_path, grKeyframesInfo* info, char* err, int errsz);

#endif  // GAITSIM_RENDER_GR_KEYFRAMES_H_
