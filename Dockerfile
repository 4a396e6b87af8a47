# bcfem in a container. Same install path as the README: tools/bootstrap.sh
# creates .venv and pip-installs bcfem with its extras.
#   docker build -t bcfem .
#   docker run bcfem make test
# The image holds the site too: /opt/bcfem/docs/_build/html (make docs).
# Without Docker: tools/container-check.sh runs this file's steps in a Debian
# bookworm chroot (docs/docker.md). It reads APT_PACKAGES, ENV, WORKDIR, the RUN
# lines and CMD from here, so keep to those instructions (and COPY . .).
FROM python:3.12-slim-bookworm

# Debian packages, with why (the slim image has none of them):
#  build-essential make git: FFCx compiles the UFL forms with gcc at run time;
#    make runs the README's targets.
#  libglu1-mesa .. libgomp1: what the gmsh wheel's libgmsh.so links
#    (readelf -d: libGLU.so.1, libGL.so.1, libX11.so.6, libXrender.so.1,
#    libXcursor.so.1, libXfixes.so.3, libXext.so.6, libXft.so.2, libXinerama.so.1,
#    libfontconfig.so.1, libgomp.so.1); without them `import gmsh` fails.
#  libegl1 libegl-mesa0 libgl1-mesa-dri: the vtk wheel (pyvista) links no GL but
#    dlopens libEGL.so.1 for off-screen rendering (VTK_DEFAULT_OPENGL_WINDOW
#    below); glvnd's libEGL then loads Mesa's EGL vendor library, which renders
#    in software with the swrast (llvmpipe) driver from libgl1-mesa-dri.
ARG APT_PACKAGES="build-essential make git \
    libglu1-mesa libgl1 libx11-6 libxrender1 libxcursor1 libxfixes3 libxext6 \
    libxft2 libxinerama1 libfontconfig1 libgomp1 \
    libegl1 libegl-mesa0 libgl1-mesa-dri"
RUN apt-get update \
 && apt-get install -y --no-install-recommends $APT_PACKAGES \
 && rm -rf /var/lib/apt/lists/*

WORKDIR /opt/bcfem
COPY . .
RUN PYTHON=python3.12 ./tools/bootstrap.sh \
 && .venv/bin/python -c "import bcfem, dolfinx; print('bcfem', bcfem.__version__, 'dolfinx', dolfinx.__version__)" \
 && make docs

ENV PATH=/opt/bcfem/.venv/bin:$PATH \
    OMPI_ALLOW_RUN_AS_ROOT=1 \
    VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
CMD ["make", "test"]
