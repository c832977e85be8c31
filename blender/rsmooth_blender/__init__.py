"""rsmooth in Blender: feature-preserving mesh denoising (Jones, Durand & Desbrun 2003) on the
selected mesh objects, from the Object menu or the 3D View's sidebar (tab "rsmooth").

The rsmooth Python package is vendored in _vendor/ (unpacked from its wheels by
blender/make_addon.py, with its compiled extension), because Blender's Python is its own and
often has no pip or network. register() puts _vendor/ first on sys.path; the package itself is
imported on first use, so a module that cannot load on this system is an error the operator
reports rather than an add-on that will not enable.
"""

bl_info = {
    "name": "rsmooth: Denoise Mesh",
    "author": "rsmooth authors",
    "version": (0, 10, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Object > Denoise (rsmooth); View3D > Sidebar > rsmooth",
    "description": "Removes noise from meshes and keeps their sharp edges (Jones et al. 2003), "
    "on an OpenCL device or the CPU",
    "doc_url": "",
    "category": "Mesh",
}

import os
import sys

if "bpy" in locals():  # a reload (F3 > Reload Scripts) re-imports the submodule
    import importlib

    importlib.reload(operators)  # noqa: F821 (defined by the first import below)
else:
    from . import operators

import bpy

VENDOR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_vendor")


def _menu(self, context):
    self.layout.separator()
    self.layout.operator(operators.OBJECT_OT_rsmooth_denoise.bl_idname, icon="MOD_SMOOTH")


def register():
    if os.path.isdir(VENDOR) and VENDOR not in sys.path:
        sys.path.insert(0, VENDOR)
    for cls in operators.CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.VIEW3D_MT_object.append(_menu)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(_menu)
    for cls in reversed(operators.CLASSES):
        bpy.utils.unregister_class(cls)
    if VENDOR in sys.path:
        sys.path.remove(VENDOR)
