// Checks the links of README.md, ARCHITECTURE.md and the book (docs/src/*.md): every relative
// link names a file that exists, and every #anchor a heading of its page (mdBook's and
// GitHub's slugs: lower case, punctuation dropped, spaces to hyphens). External links are not
// fetched (the tests run offline). Prints each broken link and exits 1 if there is one.
//
//   node docs/check-links.mjs
import { existsSync, readFileSync, readdirSync } from "node:fs";
import { dirname, join, relative, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const root = resolve(dirname(fileURLToPath(import.meta.url)), "..");
const pages = [
  "README.md",
  "ARCHITECTURE.md",
  ...readdirSync(join(root, "docs/src"))
    .filter((f) => f.endsWith(".md"))
    .map((f) => `docs/src/${f}`),
];

/** The text of a page with `{{#include path}}` expanded (as mdBook does) and code removed. */
function prose(file) {
  const text = readFileSync(file, "utf8").replace(/\{\{#include ([^}]+)\}\}/g, (_, path) =>
    readFileSync(resolve(dirname(file), path.trim()), "utf8"),
  );
  return text.replace(/```[\s\S]*?```/g, "").replace(/`[^`\n]*`/g, "");
}

function slug(heading) {
  return heading
    .trim()
    .toLowerCase()
    .replace(/[^\p{L}\p{N}\s_-]/gu, "")
    .replace(/\s+/g, "-");
}

function anchors(file) {
  return new Set(
    prose(file)
      .split("\n")
      .filter((l) => /^#{1,6} /.test(l))
      .map((l) => slug(l.replace(/^#+ /, ""))),
  );
}

let broken = 0;
let checked = 0;
for (const page of pages) {
  const file = join(root, page);
  for (const match of prose(file).matchAll(/!?\[[^\]]*\]\(([^)\s]+)(?:\s+"[^"]*")?\)/g)) {
    const target = match[1];
    if (/^(https?|mailto):/.test(target)) continue;
    checked += 1;
    const [path, anchor] = target.split("#");
    const linked = path ? resolve(dirname(file), decodeURIComponent(path)) : file;
    let problem = null;
    if (!existsSync(linked)) {
      problem = "no such file";
    } else if (anchor && linked.endsWith(".md") && !anchors(linked).has(anchor)) {
      problem = `no heading #${anchor} in ${relative(root, linked)}`;
    }
    if (problem) {
      broken += 1;
      console.log(`${page}: ${target}: ${problem}`);
    }
  }
}
console.log(`links: ${checked} checked in ${pages.length} pages, ${broken} broken`);
process.exit(broken ? 1 : 0);
