# remeshd in a container. Both stages install through scripts/setup.sh, the same step as the
# README's quick start, so the two cannot drift.
#   docker build -t remeshd . && docker run -p 8080:8080 -v remeshd-data:/var/lib/remeshd remeshd
FROM debian:bookworm-slim AS build
WORKDIR /src
COPY scripts/setup.sh scripts/setup.sh
COPY web/package.json web/package-lock.json web/
RUN bash scripts/setup.sh deps
COPY . .
RUN REMESH_BUILD_DIR=/src/build \
    REMESH_CMAKE_ARGS="-DREMESH_BUILD_TESTS=OFF -DREMESH_BUILD_BENCH=OFF" \
    bash scripts/setup.sh build

FROM debian:bookworm-slim
COPY scripts/setup.sh /tmp/setup.sh
RUN bash /tmp/setup.sh deps --runtime && rm -rf /var/lib/apt/lists/* /tmp/setup.sh \
    && useradd --system --home-dir /var/lib/remeshd --create-home remeshd
COPY --from=build /src/build/bin/remeshd /src/build/bin/remesh /opt/remeshd/bin/
COPY --from=build /src/build/web /opt/remeshd/web
USER remeshd
ENV REMESHD_HOST=0.0.0.0 \
    REMESHD_PORT=8080 \
    REMESHD_DATA_DIR=/var/lib/remeshd \
    REMESHD_WEB_ROOT=/opt/remeshd/web
VOLUME /var/lib/remeshd
EXPOSE 8080
HEALTHCHECK --interval=30s --timeout=5s --start-period=5s \
  CMD curl -fsS http://127.0.0.1:8080/healthz || exit 1
ENTRYPOINT ["/opt/remeshd/bin/remeshd"]
