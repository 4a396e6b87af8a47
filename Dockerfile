# bcfem in a container. Same install path as the README: tools/bootstrap.sh
# creates .venv and pip-installs bcfem with its extras.
#   docker build -t bcfem .
#   docker run bcfem make test
FROM python:3.12-slim-bookworm

# gcc and the Python headers: FFCx compiles the UFL forms at run time
RUN apt-get update \
 && apt-get install -y --no-install-recommends build-essential make git \
 && rm -rf /var/lib/apt/lists/*

WORKDIR /opt/bcfem
COPY . .
RUN PYTHON=python3.12 ./tools/bootstrap.sh \
 && .venv/bin/python -c "import bcfem, dolfinx; print('bcfem', bcfem.__version__, 'dolfinx', dolfinx.__version__)"

ENV PATH=/opt/bcfem/.venv/bin:$PATH \
    OMPI_ALLOW_RUN_AS_ROOT=1 \
    VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow
CMD ["make", "test"]
