// zstd for @mcap/core's readers (canyon writes zstd-compressed chunks): fzstd, a pure-JavaScript zstd decoder from
// the npm registry, independent of the libzstd canyon links.
import { decompress } from "fzstd";

export const decompressHandlers = {
  zstd: (buffer, decompressedSize) => decompress(buffer, new Uint8Array(Number(decompressedSize))),
};
