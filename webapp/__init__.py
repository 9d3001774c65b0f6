"""The FaçAID site: a Django project (accounts, facades with its JSON API) that hands heavy work to `worker`."""
