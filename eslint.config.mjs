// ESLint's configuration for the browser viewer's code (volumen/web/static: ES modules in the browser).
// `make lint-web` and tests/web/test_lint.py run it with the ESLint that `make web-deps` installs into
// .web-deps/, where this file finds @eslint/js and globals too (the repository has no node_modules of its own).
import { createRequire } from 'node:module';

const require = createRequire(new URL('./.web-deps/package.json', import.meta.url));
const js = require('@eslint/js');
const globals = require('globals');

export default [
  {
    files: ['volumen/web/static/**/*.js'],
    ...js.configs.recommended,
    languageOptions: {
      ecmaVersion: 2022,
      sourceType: 'module',
      globals: { ...globals.browser },
    },
    rules: {
      ...js.configs.recommended.rules,
      eqeqeq: 'error',
      'no-var': 'error',
      'prefer-const': 'error',
      'no-shadow': 'error',
      // a callback may name a const declared further down the same function (main.js: the panel and the XR
      // view refer to each other); a use in the same scope before the declaration is an error
      'no-use-before-define': ['error', { functions: false, classes: true, variables: false }],
      'no-unused-expressions': 'error',
      'no-implicit-coercion': ['error', { allow: ['!!'] }],
      'object-shorthand': 'error',
    },
  },
];
