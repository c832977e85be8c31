/* rsmooth_model_check: a learned model file read as the stage would read it, so a program can
 * refuse a bad file before it reads any mesh. */
#include "learned/learned.h"

#include <string.h>

rsmooth_status rsmooth_model_check(const void *bytes, size_t size, rsmooth_model_info *info,
                                   rsmooth_error *error) {
    static const char where[] = "rsmooth_model_check";
    rs_error_clear(error);
    if (!bytes && size > 0)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where, "bytes is NULL");
    if (info && info->struct_size < sizeof *info)
        return rs_fail(error, RSMOOTH_ERROR_INVALID_ARGUMENT, where,
                       "info.struct_size %zu is too small (sizeof(rsmooth_model_info) is %zu)",
                       info->struct_size, sizeof *info);
    rs_learned_model model;
    rsmooth_status st = bytes ? rs_learned_model_read(bytes, size, &model, error, "the model")
                              : rs_learned_model_builtin(&model, error);
    if (st != RSMOOTH_OK)
        return st;
    if (info) {
        info->stages = (int)model.stage_count;
        info->parameters = model.parameters;
        info->format_version = model.format_version;
        info->layout = model.layout;
        memcpy(info->manifest, model.manifest, sizeof info->manifest);
    }
    rs_learned_model_free(&model);
    return RSMOOTH_OK;
}
